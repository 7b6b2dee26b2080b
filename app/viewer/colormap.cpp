#include "app/viewer/colormap.h"

#include <algorithm>
#include <cmath>

namespace lancer::viewer {

const char* viewModeName(ViewMode m) {
    switch (m) {
        case ViewMode::Color:
            return "colour";
        case ViewMode::PrimTests:
            return "primitive tests";
        case ViewMode::RegionVisits:
            return "region visits";
        case ViewMode::TimeUs:
            return "time (us)";
    }
    return "?";
}

const char* viewModeWord(ViewMode m) {
    static const char* words[] = {"color", "prim_tests", "region_visits", "time"};
    return words[int(m)];
}

std::optional<ViewMode> viewModeOf(const std::string& word) {
    for (int i = 0; i < kViewModeCount; ++i)
        if (word == viewModeWord(ViewMode(i))) return ViewMode(i);
    return std::nullopt;
}

const std::array<glm::vec3, 8>& colormapStops() {
    static const std::array<glm::vec3, 8> stops = {
        glm::vec3(0, 0, 4) / 255.0f,      glm::vec3(40, 11, 84) / 255.0f,
        glm::vec3(101, 21, 110) / 255.0f, glm::vec3(159, 42, 99) / 255.0f,
        glm::vec3(212, 72, 66) / 255.0f,  glm::vec3(245, 125, 21) / 255.0f,
        glm::vec3(250, 193, 39) / 255.0f, glm::vec3(252, 255, 164) / 255.0f};
    return stops;
}

glm::vec3 colormap(float v) {
    const auto& s = colormapStops();
    float x = std::clamp(v, 0.0f, 1.0f) * float(s.size() - 1);
    int i = std::min(int(std::floor(x)), int(s.size()) - 2);
    float f = x - float(i);
    return s[size_t(i)] * (1.0f - f) + s[size_t(i) + 1] * f;
}

glm::vec3 levelColor(int level) {
    if (level < 0) level = 0;
    if (level >= kLevelRamp) return glm::vec3(1.0f);
    const float hue = 0.8f * float(level) / float(kLevelRamp - 1) * 6.0f;  // red .. violet
    const float x = 1.0f - std::abs(std::fmod(hue, 2.0f) - 1.0f);
    glm::vec3 c;
    switch (int(hue) % 6) {
        case 0:
            c = {1, x, 0};
            break;
        case 1:
            c = {x, 1, 0};
            break;
        case 2:
            c = {0, 1, x};
            break;
        case 3:
            c = {0, x, 1};
            break;
        case 4:
            c = {x, 0, 1};
            break;
        default:
            c = {1, 0, x};
            break;
    }
    return 0.25f + 0.75f * c;  // never black: a line on a dark image
}

float countPosition(double count) {
    if (!(count > 1.0)) return 0.0f;
    return std::clamp(float(std::log10(count)) / float(kCountDecades), 0.0f, 1.0f);
}

glm::vec3 countColor(double count) { return colormap(0.3f + 0.7f * countPosition(count)); }

float costPosition(double count) {
    if (!(count > 1.0)) return 0.0f;
    return std::clamp(float(std::log10(count)) / float(kCostDecades), 0.0f, 1.0f);
}

glm::vec3 costColor(double count) {
    if (!(count > 0.0)) return kNoCostColor;
    return colormap(0.3f + 0.7f * costPosition(count));
}

float decadeScale(float p99) {
    if (!(p99 > 1.0f)) return 1.0f;
    const float d = std::pow(10.0f, std::ceil(std::log10(p99) - 1e-6f));
    return d < p99 ? d * 10.0f : d;
}

std::vector<float> heatChannel(const Image& img, ViewMode mode, int rowBegin, int rowEnd) {
    size_t first, last;
    img.pixelRange(rowBegin, rowEnd, first, last);
    auto rows = [&](const auto& channel) {
        return std::vector<float>(channel.begin() + std::ptrdiff_t(first),
                                  channel.begin() + std::ptrdiff_t(last));
    };
    switch (mode) {
        case ViewMode::Color:
            break;
        case ViewMode::PrimTests:
            return rows(img.primTests);
        case ViewMode::RegionVisits:
            return rows(img.regionVisits);
        case ViewMode::TimeUs:
            return rows(img.timeUs);
    }
    return {};
}

float autoScale(const std::vector<float>& heat) {
    if (heat.empty()) return 1.0f;
    std::vector<float> v = heat;
    const auto at = v.begin() + std::ptrdiff_t((v.size() - 1) * 99 / 100);
    std::nth_element(v.begin(), at, v.end());
    return std::max(1.0f, *at);
}

float heatValue(float count, float scale, bool logScale) {
    scale = scale > 0.0f ? scale : 1.0f;
    const float v =
        logScale ? std::log1p(std::max(0.0f, count)) / std::log1p(scale) : count / scale;
    return std::clamp(v, 0.0f, 1.0f);
}

const std::array<glm::vec3, 9>& divergingStops() {
    static const std::array<glm::vec3, 9> stops = {
        glm::vec3(178, 24, 43) / 255.0f,   glm::vec3(214, 96, 77) / 255.0f,
        glm::vec3(244, 165, 130) / 255.0f, glm::vec3(253, 219, 199) / 255.0f,
        glm::vec3(247, 247, 247) / 255.0f, glm::vec3(209, 229, 240) / 255.0f,
        glm::vec3(146, 197, 222) / 255.0f, glm::vec3(67, 147, 195) / 255.0f,
        glm::vec3(33, 102, 172) / 255.0f};
    return stops;
}

glm::vec3 divergingColor(float v) {
    const auto& s = divergingStops();
    float x = (std::clamp(v, -1.0f, 1.0f) + 1.0f) * 0.5f * float(s.size() - 1);
    int i = std::min(int(std::floor(x)), int(s.size()) - 2);
    float f = x - float(i);
    return s[size_t(i)] * (1.0f - f) + s[size_t(i) + 1] * f;
}

float diffValue(float d, float scale, bool logScale) {
    scale = scale > 0.0f ? scale : 1.0f;
    const float v =
        logScale ? std::copysign(std::log1p(std::abs(d)) / std::log1p(scale), d) : d / scale;
    return std::clamp(v, -1.0f, 1.0f);
}

}  // namespace lancer::viewer
