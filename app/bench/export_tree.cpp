#include "app/bench/export_tree.h"

#include <charconv>

namespace lancer::bench {

std::vector<int> operands(const CsgTree& tree, int node) {
    const CsgNode& top = tree.nodes[size_t(node)];
    std::vector<int> out;
    if (top.op == Op::Difference) {
        std::vector<int> subtracted;
        int a = node;
        while (tree.nodes[size_t(a)].op == Op::Difference) {
            subtracted.push_back(tree.nodes[size_t(a)].right);
            a = tree.nodes[size_t(a)].left;
        }
        out.push_back(a);
        out.insert(out.end(), subtracted.rbegin(), subtracted.rend());
        return out;
    }
    std::vector<int> stack{top.right, top.left};
    while (!stack.empty()) {
        const int i = stack.back();
        stack.pop_back();
        const CsgNode& c = tree.nodes[size_t(i)];
        if (c.op == top.op) {
            stack.push_back(c.right);
            stack.push_back(c.left);
        } else {
            out.push_back(i);
        }
    }
    return out;
}

std::string shortest(double v) {
    if (v == 0.0) return "0";
    char buf[40];
    const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
    return std::string(buf, end);
}

}  // namespace lancer::bench
