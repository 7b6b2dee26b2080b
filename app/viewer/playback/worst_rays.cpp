#include "app/viewer/playback/worst_rays.h"

#include <algorithm>
#include <numeric>

namespace lancer::viewer::playback {

std::vector<CostlyPixel> costliestPixels(const Image& img, RayCost by, size_t n) {
    const size_t count = size_t(img.width) * size_t(img.height);
    if (img.primTests.size() != count || img.regionVisits.size() != count ||
        img.timeUs.size() != count)
        return {};
    auto cost = [&](size_t i) -> double {
        switch (by) {
            case RayCost::Tests:
                return double(img.primTests[i]);
            case RayCost::Visits:
                return double(img.regionVisits[i]);
            case RayCost::Time:
                break;
        }
        return double(img.timeUs[i]);
    };
    std::vector<size_t> order(count);
    std::iota(order.begin(), order.end(), size_t(0));
    const size_t k = std::min(n, count);
    std::partial_sort(order.begin(), order.begin() + ptrdiff_t(k), order.end(),
                      [&](size_t a, size_t b) {
                          const double ca = cost(a), cb = cost(b);
                          return ca != cb ? ca > cb : a < b;
                      });
    std::vector<CostlyPixel> out;
    out.reserve(k);
    for (size_t j = 0; j < k; ++j) {
        const size_t i = order[j];
        out.push_back({int(i % size_t(img.width)), int(i / size_t(img.width)), img.primTests[i],
                       img.regionVisits[i], img.timeUs[i]});
    }
    return out;
}

}  // namespace lancer::viewer::playback
