#include "app/viewer/panels/tree_panel.h"

#include <algorithm>
#include <cstdio>
#include <string>

namespace lancer::viewer {

namespace {

/// "1234567" as "1.23M", "45.6k": the counts' columns stay narrow.
std::string shortCount(uint64_t v) {
    char buf[32];
    if (v < 10000)
        std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(v));
    else if (v < 10000000)
        std::snprintf(buf, sizeof buf, "%.1fk", double(v) / 1e3);
    else
        std::snprintf(buf, sizeof buf, "%.2fM", double(v) / 1e6);
    return buf;
}

bool hasPrefix(const std::vector<size_t>& v, const std::vector<size_t>& prefix) {
    return v.size() >= prefix.size() && std::equal(prefix.begin(), prefix.end(), v.begin());
}

}  // namespace

std::optional<uint32_t> TreeBrowser::draw(const StructureView* sv, const RegionCosts* costs,
                                          int64_t selected) {
    rows_.clear();
    rowsDrawn_ = 0;
    clicked_.reset();
    if (!sv) {
        ImGui::TextDisabled("no structure yet");
        return std::nullopt;
    }
    if (sv != view_ || sv->regionCount() != viewRegions_) {
        // A new structure: its nodes are others.
        view_ = sv;
        viewRegions_ = sv->regionCount();
        open_.clear();
        followed_ = -1;
        hasTarget_ = false;
    }
    const std::vector<StructureTree> trees = sv->trees();
    if (trees.empty()) {
        ImGui::TextDisabled("%s: one region, no tree", schemeName(sv->scheme()));
        return std::nullopt;
    }
    tree_ = std::clamp(tree_, 0, int(trees.size()) - 1);
    costs_ = costs && costs->regions() == sv->regionCount() ? costs : nullptr;

    // A region selected elsewhere: open the path to its node (in the tree shown, else the first
    // tree holding it) and bring its row into view.
    if (selected != followed_) {
        followed_ = selected;
        hasTarget_ = false;
        if (selected >= 0) {
            for (int k = 0; k < int(trees.size()); ++k) {
                const int t = (tree_ + k) % int(trees.size());
                const auto path = sv->treePath(trees[size_t(t)], uint32_t(selected));
                if (!path) continue;
                tree_ = t;
                target_ = *path;
                hasTarget_ = scrollTo_ = true;
                for (size_t n = 0; n < path->size(); ++n)
                    open_.insert(std::vector<size_t>(path->begin(), path->begin() + ptrdiff_t(n)));
                break;
            }
        }
    }

    if (trees.size() > 1) {
        std::vector<const char*> names;
        for (const StructureTree& t : trees) names.push_back(t.name.c_str());
        int t = tree_;
        if (ImGui::Combo("tree", &t, names.data(), int(names.size())) && t != tree_) setTree(t);
    }
    ImGui::TextDisabled(costs_ ? "visits, tests: last complete image"
                               : "visits, tests: once the image is complete");

    const ImGuiTableFlags flags = ImGuiTableFlags_ScrollY | ImGuiTableFlags_RowBg |
                                  ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingFixedFit;
    const float rowH = ImGui::GetTextLineHeightWithSpacing();
    if (!ImGui::BeginTable("structure tree", 4, flags, ImVec2(0.0f, rowH * 16.5f)))
        return std::nullopt;
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("node", ImGuiTableColumnFlags_WidthStretch);
    const float num = ImGui::CalcTextSize("000.0k").x;
    ImGui::TableSetupColumn("prims", ImGuiTableColumnFlags_WidthFixed,
                            ImGui::CalcTextSize("prims").x);
    ImGui::TableSetupColumn("visits", ImGuiTableColumnFlags_WidthFixed, num);
    ImGui::TableSetupColumn("tests", ImGuiTableColumnFlags_WidthFixed, num);
    ImGui::TableHeadersRow();
    // Narrow steps, and none past kIndentedLevels: a BSP 30 levels deep keeps its labels in a
    // 250-unit column (the labels say the level).
    ImGui::PushStyleVar(ImGuiStyleVar_IndentSpacing, 8.0f);
    std::vector<size_t> path;
    node(*sv, trees[size_t(tree_)].root, path);
    ImGui::PopStyleVar();
    ImGui::EndTable();
    return clicked_;
}

void TreeBrowser::counts(const TreeNode& n) {
    ImGui::TableSetColumnIndex(1);
    if (n.prims >= 0)
        ImGui::TextUnformatted(shortCount(uint64_t(n.prims)).c_str());
    else
        ImGui::TextDisabled("-");
    if (!costs_) return;
    // A region's own counts (a BVH inner node is entered, but tests nothing), else the
    // regions below it.
    uint32_t lo = 0, hi = 0;
    if (n.region >= 0) {
        lo = uint32_t(n.region);
        hi = lo + 1;
    } else if (n.ranged) {
        lo = n.regionLo;
        hi = n.regionHi;
    }
    if (hi <= lo) return;
    ImGui::TableSetColumnIndex(2);
    ImGui::TextUnformatted(shortCount(costs_->visits(lo, hi)).c_str());
    ImGui::TableSetColumnIndex(3);
    ImGui::TextUnformatted(shortCount(costs_->tests(lo, hi)).c_str());
}

void TreeBrowser::node(const StructureView& sv, const TreeNode& n, std::vector<size_t>& path) {
    ImGui::TableNextRow();
    ImGui::TableSetColumnIndex(0);
    ++rowsDrawn_;
    const bool target = hasTarget_ && path == target_;
    ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_SpanFullWidth | ImGuiTreeNodeFlags_OpenOnArrow |
                               ImGuiTreeNodeFlags_OpenOnDoubleClick;
    const bool push = n.children > 0 && path.size() < kIndentedLevels;
    if (n.children == 0) flags |= ImGuiTreeNodeFlags_Leaf;
    if (!push) flags |= ImGuiTreeNodeFlags_NoTreePushOnOpen;
    if (target) flags |= ImGuiTreeNodeFlags_Selected;
    const bool wasOpen = n.children > 0 && open_.count(path) > 0;
    if (n.children > 0) ImGui::SetNextItemOpen(wasOpen, ImGuiCond_Always);
    // Unique among the rows a tree push groups (the rows past kIndentedLevels share one):
    // the depth and the index among the siblings.
    const uint64_t key = (uint64_t(path.size()) << 40) | (path.empty() ? 0 : path.back() + 1);
    const void* id = reinterpret_cast<const void*>(uintptr_t(key));
    const std::string label = sv.describe(n);
    const bool isOpen = ImGui::TreeNodeEx(id, flags, "%s", label.c_str());
    if (ImGui::IsItemClicked() && !ImGui::IsItemToggledOpen() && n.region >= 0)
        clicked_ = uint32_t(n.region);
    if (ImGui::IsItemHovered()) {
        if (n.region >= 0)
            ImGui::SetTooltip("%s\nclick: select region %lld",
                              sv.toString(uint32_t(n.region)).c_str(),
                              static_cast<long long>(n.region));
        else
            ImGui::SetTooltip("%s %s, depth %d, %zu children; regions %u..%u below",
                              treeNodeKindName(n.kind), label.c_str(), n.depth, n.children,
                              n.regionLo, n.regionHi - 1);
    }
    if (n.region >= 0) {
        const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
        rows_[n.region] = ImVec2(0.5f * (lo.x + hi.x), 0.5f * (lo.y + hi.y));
    }
    if (target && scrollTo_) {
        ImGui::SetScrollHereY(0.5f);
        scrollTo_ = false;
    }
    if (n.children > 0 && isOpen != wasOpen) {
        if (isOpen)
            open_.insert(path);
        else
            open_.erase(path);
    }
    counts(n);
    if (n.children > 0 && isOpen) {
        children(sv, n, path);
        if (push) ImGui::TreePop();
    }
}

void TreeBrowser::children(const StructureView& sv, const TreeNode& n, std::vector<size_t>& path) {
    // The children drawn whole: the open ones (their subtrees make rows of other heights) and
    // the selection's. The others, in runs between them, are one row each: a long run goes
    // through the clipper, which asks only for the rows in view.
    std::vector<size_t> whole;
    path.push_back(0);
    for (auto it = open_.lower_bound(path); it != open_.end(); ++it) {
        if (!hasPrefix(*it, std::vector<size_t>(path.begin(), path.end() - 1))) break;
        if (it->size() == path.size()) whole.push_back(it->back());
    }
    path.pop_back();
    if (hasTarget_ && target_.size() > path.size() && hasPrefix(target_, path))
        whole.push_back(target_[path.size()]);
    std::sort(whole.begin(), whole.end());
    whole.erase(std::unique(whole.begin(), whole.end()), whole.end());
    auto one = [&](size_t i) {
        path.push_back(i);
        node(sv, sv.treeChild(n, i), path);
        path.pop_back();
    };
    size_t i = 0;
    for (size_t k = 0; k <= whole.size(); ++k) {
        const size_t end = k < whole.size() ? std::min(whole[k], n.children) : n.children;
        if (end - i > kClipAt) {
            ImGuiListClipper clipper;
            clipper.Begin(int(end - i));
            while (clipper.Step())
                for (int r = clipper.DisplayStart; r < clipper.DisplayEnd; ++r) one(i + size_t(r));
            clipper.End();
        } else {
            for (size_t j = i; j < end; ++j) one(j);
        }
        if (k < whole.size() && whole[k] < n.children) one(whole[k]);
        i = end + 1;
    }
}

}  // namespace lancer::viewer
