#include "app/viewer/compare/rebuild_diff.h"

#include <algorithm>
#include <cmath>

#include "app/cli/param_table.h"

namespace lancer::viewer::compare {

namespace {

bool sameCamera(const Camera& a, const Camera& b) {
    return a.from == b.from && a.at == b.at && a.up == b.up && a.fov == b.fov &&
           a.projection == b.projection && a.orthoHeight == b.orthoHeight;
}

bool sameShading(const ShadingOptions& a, const ShadingOptions& b) {
    return a.bounces == b.bounces && a.shadows == b.shadows && a.reflections == b.reflections &&
           a.refractions == b.refractions && a.offsetScale == b.offsetScale &&
           a.precision == b.precision;
}

template <class Counters>
CounterSums sums(const Counters& img, int rows) {
    CounterSums s;
    const size_t n = size_t(std::clamp(rows, 0, img.height)) * size_t(img.width);
    for (size_t i = 0; i < n; ++i) {
        s.primTests += img.primTests[i];
        s.regionVisits += img.regionVisits[i];
        s.timeUs += double(img.timeUs[i]);
    }
    s.pixels = n;
    return s;
}

/// Pixel index range of rows [rowBegin, rowEnd) (-1: to the last) of a width x height image.
void rowRange(int width, int height, int rowBegin, int rowEnd, size_t& first, size_t& last) {
    if (rowEnd < 0 || rowEnd > height) rowEnd = height;
    rowBegin = std::clamp(rowBegin, 0, rowEnd);
    first = size_t(rowBegin) * size_t(width);
    last = size_t(rowEnd) * size_t(width);
}

}  // namespace

const char* abViewKey(AbView v) {
    switch (v) {
        case AbView::New:
            return "new";
        case AbView::Old:
            return "old";
        case AbView::Diff:
            return "diff";
    }
    return "?";
}

std::optional<AbView> abViewOf(const std::string& key) {
    for (int i = 0; i < kAbViewCount; ++i)
        if (key == abViewKey(AbView(i))) return AbView(i);
    return std::nullopt;
}

bool RenderKey::operator==(const RenderKey& o) const {
    return spec == o.spec && width == o.width && height == o.height &&
           sameCamera(camera, o.camera) && sameShading(shading, o.shading);
}

CounterImage CounterImage::of(const Image& img, const RenderKey& key, const BuildParams& params,
                              const std::vector<PassRecord>& passes) {
    CounterImage c;
    c.width = img.width;
    c.height = img.height;
    c.primTests = img.primTests;
    c.regionVisits = img.regionVisits;
    c.timeUs = img.timeUs;
    for (const PassRecord& p : passes) {
        c.counters += p.counters;
        c.renderMs += p.renderMs;
    }
    c.params = params;
    c.key = key;
    return c;
}

CounterSums sumRows(const Image& img, int rows) { return sums(img, rows); }
CounterSums sumRows(const CounterImage& img, int rows) { return sums(img, rows); }

std::vector<float> counterChannel(const CounterImage& a, ViewMode mode, int rowBegin, int rowEnd) {
    size_t first, last;
    rowRange(a.width, a.height, rowBegin, rowEnd, first, last);
    std::vector<float> out;
    out.reserve(last - first);
    for (size_t i = first; i < last; ++i)
        out.push_back(mode == ViewMode::PrimTests      ? float(a.primTests[i])
                      : mode == ViewMode::RegionVisits ? float(a.regionVisits[i])
                                                       : a.timeUs[i]);
    return out;
}

std::vector<float> diffChannel(const CounterImage& a, const Image& b, ViewMode mode, int rowBegin,
                               int rowEnd, int validRows) {
    size_t first, last;
    rowRange(b.width, b.height, rowBegin, rowEnd, first, last);
    const bool sameSize = a.width == b.width && a.height == b.height;
    const size_t valid =
        sameSize ? size_t(std::clamp(validRows, 0, b.height)) * size_t(b.width) : 0;
    std::vector<float> out(last - first, kNoDiff);
    if (mode == ViewMode::Color) return {};
    for (size_t i = first; i < std::min(last, valid); ++i) {
        // In double: a difference of two large counts is exact before it is rounded once.
        double d = 0.0;
        if (mode == ViewMode::PrimTests)
            d = double(a.primTests[i]) - double(b.primTests[i]);
        else if (mode == ViewMode::RegionVisits)
            d = double(a.regionVisits[i]) - double(b.regionVisits[i]);
        else
            d = double(a.timeUs[i]) - double(b.timeUs[i]);
        out[i - first] = float(d);
    }
    return out;
}

float diffAutoScale(const std::vector<float>& diff) {
    std::vector<float> mags;
    mags.reserve(diff.size());
    for (float d : diff)
        if (d < kNoDiff) mags.push_back(std::abs(d));
    return autoScale(mags);
}

std::string paramChanges(const BuildParams& a, const BuildParams& b) {
    cli::Knobs ka, kb;
    ka.build = a;
    kb.build = b;
    std::string out;
    for (const cli::ParamDesc& d : cli::paramTable()) {
        if (d.effect != cli::ChangeEffect::Rebuild || !d.get || d.get(ka) == d.get(kb)) continue;
        if (!cli::applies(d, ka) && !cli::applies(d, kb)) continue;
        out += (out.empty() ? "" : ", ") + std::string(d.flag + 2) + " " + cli::formatValue(d, ka) +
               " -> " + cli::formatValue(d, kb);
    }
    return out.empty() ? "same parameters" : out;
}

void RebuildDiff::rebuilt(const Image& shown, bool complete, const RenderKey& key,
                          const BuildParams& params, const std::vector<PassRecord>& passes) {
    rebuiltOnce_ = true;
    lastIncomplete_ = !complete;
    if (!complete) return;  // a partial image is never compared; an older complete one may be
    old_ = CounterImage::of(shown, key, params, passes);
    ++generation_;
}

void RebuildDiff::clear() {
    old_.reset();
    rebuiltOnce_ = lastIncomplete_ = false;
    ++generation_;
}

AbStatus RebuildDiff::status(const RenderKey& key, int doneRows) const {
    AbStatus s;
    s.height = key.height;
    if (!old_) {
        s.note = !rebuiltOnce_ ? "no rebuild yet: change a parameter (max-level, max-objects, ...) "
                                 "and the image before it is A"
                 : lastIncomplete_ ? "no complete old image to compare: the image was still "
                                     "rendering when the structure changed"
                                   : "no old image to compare";
        return s;
    }
    if (!(old_->key == key)) {
        s.note = "the view changed since the old image (camera, size, shading): nothing to compare";
        return s;
    }
    s.comparable = true;
    s.rows = std::clamp(doneRows, 0, key.height);
    if (s.rows == 0)
        s.note = "the new image is in its coarse passes: no row to compare yet";
    else if (s.rows < key.height)
        s.note = "rows 0-" + std::to_string(s.rows - 1) + " of " + std::to_string(key.height) +
                 " compared: the new image is still rendering";
    return s;
}

}  // namespace lancer::viewer::compare
