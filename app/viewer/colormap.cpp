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
    float m = 1.0f;
    for (float v : heat) m = std::max(m, v);
    return m;
}

}  // namespace lancer::viewer
