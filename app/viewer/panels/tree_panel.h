// The tree browser ("Structure tree" panel): the structure's trees (StructureView::trees: the
// regular BSP and directory, the irregular scheme's screen BSPs with their zones and slabs,
// the BVH) as expandable ImGui trees, each row with its primitives and the last complete
// image's region visits and tests below it. Only open nodes' children are listed, a long
// child list through ImGui's clipper: a tree of millions of nodes costs the rows on screen.
// The selection is linked both ways: a click on a region's row selects it, and a region
// selected elsewhere (the image, --select, the inspector, the playback) opens its path and
// highlights its row.
#pragma once

#include <imgui.h>

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "engine/accel/structure_view.h"
#include "engine/render/region_costs.h"

namespace lancer::viewer {

class TreeBrowser {
  public:
    /// A child list longer than this goes through ImGui's clipper.
    static constexpr size_t kClipAt = 32;
    /// Levels indented; deeper nodes line up under the last indented one.
    static constexpr size_t kIndentedLevels = 5;

    /// The panel's content (between its Begin and End): the trees of `sv` (null: no structure
    /// yet) with the counts of `costs` (null: none for this structure; of which rays says
    /// `rays`), the row of region `selected` (-1: none) opened to and highlighted. Returns the
    /// region whose row was clicked.
    std::optional<uint32_t> draw(const StructureView* sv, const RegionCosts* costs,
                                 int64_t selected);

    /// The tree shown (an index of sv->trees()).
    int tree() const { return tree_; }
    /// Show tree `t` (as its combo does), its nodes closed; the selection opens in it next.
    void setTree(int t) {
        tree_ = t;
        open_.clear();
        followed_ = -1;
    }
    /// Where the last draw() put each region's row (screen coordinates of its centre), for the
    /// rows it drew.
    const std::map<int64_t, ImVec2>& rows() const { return rows_; }
    /// The child-index paths of the open nodes.
    const std::set<std::vector<size_t>>& open() const { return open_; }
    /// Rows the last draw() submitted (what a frame costs).
    size_t rowsDrawn() const { return rowsDrawn_; }

  private:
    void node(const StructureView& sv, const TreeNode& n, std::vector<size_t>& path);
    void children(const StructureView& sv, const TreeNode& n, std::vector<size_t>& path);
    void counts(const TreeNode& n);

    const StructureView* view_ = nullptr;
    size_t viewRegions_ = 0;
    int tree_ = 0;
    std::set<std::vector<size_t>> open_;
    int64_t followed_ = -1;       ///< the selection last opened to
    std::vector<size_t> target_;  ///< its node's path
    bool hasTarget_ = false, scrollTo_ = false;
    const RegionCosts* costs_ = nullptr;
    std::optional<uint32_t> clicked_;
    std::map<int64_t, ImVec2> rows_;
    size_t rowsDrawn_ = 0;
};

}  // namespace lancer::viewer
