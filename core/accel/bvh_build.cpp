// Binned SAH (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies"): at each node
// the centroids are binned along every axis and the plane between bins with the least surface-area cost
// wins, or the node becomes a leaf when that is cheaper.
#include "core/accel/bvh.hpp"

#include "core/base/error.hpp"

#include <algorithm>
#include <bit>
#include <string>

namespace vitrine::accel {

namespace {

struct Prim {
    BvhBox box;
    glm::vec3 centroid;
};

struct Split {
    int axis = -1;
    uint32_t bin = 0;  // the left side takes bins [0, bin)
    float cost = 0.0f; // sum of half area x count of both sides
};

class Builder {
public:
    Builder(std::span<const BvhBuildTriangle> triangles, const BvhBuildOptions& options, BvhArrays& out)
        : mTriangles(triangles), mOptions(options), mOut(out) {
        if (options.bins < 2 || options.bins > 256 || options.maxLeafSize < 1 || options.maxDepth < 1 ||
            options.maxDepth > kMaxDepth)
            throw InternalError("BVH build: bins must be in [2, 256], maxLeafSize at least 1, maxDepth in [1, " +
                                std::to_string(kMaxDepth) + "]");
        mBinBoxes.resize(options.bins);
        mBinCounts.resize(options.bins);
        mRightCost.resize(options.bins);
        mPrims.reserve(triangles.size());
        for (const BvhBuildTriangle& t : triangles) {
            Prim p;
            p.box.expand(t.v0);
            p.box.expand(t.v1);
            p.box.expand(t.v2);
            p.centroid = 0.5f * (p.box.min + p.box.max);
            mPrims.push_back(p);
        }
        mOrder.resize(triangles.size());
        for (uint32_t i = 0; i < mOrder.size(); ++i)
            mOrder[i] = i;
    }

    BvhBottomLevel run() {
        BvhBottomLevel level;
        level.firstNode = static_cast<uint32_t>(mOut.nodes.size());
        level.firstTriangle = static_cast<uint32_t>(mOut.triangles.size());
        const uint32_t n = static_cast<uint32_t>(mOrder.size());
        BvhBox box, centroids;
        bounds(0, n, box, centroids);
        level.bounds = box;
        mRootArea = std::max(box.halfArea(), 1e-30f);
        BvhChild root = n == 0 ? BvhChild{} : build(0, n, 1, box, centroids);
        if (root.absent() || root.leaf()) {
            // The root must be a node: a lone leaf goes to its slot A, slot B stays empty.
            level.root = static_cast<uint32_t>(mOut.nodes.size());
            GpuBvhNode node{};
            setChild(node, 0, root);
            setChild(node, 1, BvhChild{});
            mOut.nodes.push_back(node);
            mMaxDepth = 1;
            mCost = root.absent() ? 0.0f : mOptions.traversalCost + static_cast<float>(n);
        } else {
            level.root = root.link;
        }
        level.nodeCount = static_cast<uint32_t>(mOut.nodes.size()) - level.firstNode;
        level.triangleCount = n;
        level.depth = mMaxDepth;
        level.sahCost = mCost;
        if (mMaxDepth > mOptions.maxDepth)
            throw InternalError("BVH build: depth " + std::to_string(mMaxDepth) + " exceeds " +
                                std::to_string(mOptions.maxDepth));
        return level;
    }

private:
    void bounds(uint32_t begin, uint32_t end, BvhBox& box, BvhBox& centroids) const {
        for (uint32_t i = begin; i < end; ++i) {
            const Prim& p = mPrims[mOrder[i]];
            box.expand(p.box);
            centroids.expand(p.centroid);
        }
    }

    uint32_t binOf(float c, float lo, float scale) const {
        int b = static_cast<int>((c - lo) * scale);
        return static_cast<uint32_t>(std::clamp(b, 0, static_cast<int>(mOptions.bins) - 1));
    }

    Split findSplit(uint32_t begin, uint32_t end, const BvhBox& centroids) {
        const uint32_t k = mOptions.bins;
        Split best;
        for (int axis = 0; axis < 3; ++axis) {
            float lo = centroids.min[axis], extent = centroids.max[axis] - lo;
            if (!(extent > 0.0f)) continue;
            float scale = static_cast<float>(k) / extent;
            std::vector<BvhBox>& boxes = mBinBoxes;
            std::vector<uint32_t>& counts = mBinCounts;
            std::fill(boxes.begin(), boxes.end(), BvhBox{});
            std::fill(counts.begin(), counts.end(), 0u);
            for (uint32_t i = begin; i < end; ++i) {
                const Prim& p = mPrims[mOrder[i]];
                uint32_t b = binOf(p.centroid[axis], lo, scale);
                boxes[b].expand(p.box);
                ++counts[b];
            }
            // rightCost[i]: the bins [i, k) as one side.
            std::vector<float>& rightCost = mRightCost;
            BvhBox right;
            uint32_t rightCount = 0;
            for (uint32_t i = k - 1; i > 0; --i) {
                right.expand(boxes[i]);
                rightCount += counts[i];
                rightCost[i] = rightCount ? right.halfArea() * static_cast<float>(rightCount) : 0.0f;
            }
            BvhBox left;
            uint32_t leftCount = 0;
            for (uint32_t i = 1; i < k; ++i) {
                left.expand(boxes[i - 1]);
                leftCount += counts[i - 1];
                if (leftCount == 0 || leftCount == end - begin) continue;
                float cost = left.halfArea() * static_cast<float>(leftCount) + rightCost[i];
                if (best.axis < 0 || cost < best.cost) best = {axis, i, cost};
            }
        }
        return best;
    }

    BvhChild leaf(uint32_t begin, uint32_t end, const BvhBox& box) {
        BvhChild c;
        c.box = box;
        c.link = static_cast<uint32_t>(mOut.triangles.size());
        c.count = end - begin;
        for (uint32_t i = begin; i < end; ++i) {
            const BvhBuildTriangle& t = mTriangles[mOrder[i]];
            mOut.triangles.push_back({glm::vec4(t.v0, 0.0f), glm::vec4(t.v1, 0.0f), glm::vec4(t.v2, 0.0f)});
            mOut.refs.push_back(t.ref);
        }
        mCost += static_cast<float>(c.count) * box.halfArea() / mRootArea;
        return c;
    }

    // Splits [begin, end) at the object median along the widest centroid axis (by index when all centroids
    // coincide). Used where SAH found no plane and where depth must stay bounded.
    uint32_t medianSplit(uint32_t begin, uint32_t end, const BvhBox& centroids) {
        uint32_t mid = begin + (end - begin) / 2;
        glm::vec3 e = centroids.max - centroids.min;
        int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
        if (e[axis] > 0.0f)
            std::nth_element(
                mOrder.begin() + begin, mOrder.begin() + mid, mOrder.begin() + end,
                [&](uint32_t a, uint32_t b) { return mPrims[a].centroid[axis] < mPrims[b].centroid[axis]; });
        return mid;
    }

    // A child covering [begin, end): a leaf, or a new inner node at `depth` (the root's is 1).
    BvhChild build(uint32_t begin, uint32_t end, uint32_t depth, const BvhBox& box, const BvhBox& centroids) {
        const uint32_t n = end - begin;
        if (n == 1) return leaf(begin, end, box);
        uint32_t mid;
        // Median splits at least halve n per level, so depth + bit_width(n) stops growing once they take
        // over; only a maxDepth below log2 of the triangle count leaves leaves bigger than maxLeafSize.
        if (depth + static_cast<uint32_t>(std::bit_width(n)) >= mOptions.maxDepth) {
            if (n <= mOptions.maxLeafSize || depth > mOptions.maxDepth) return leaf(begin, end, box);
            mid = medianSplit(begin, end, centroids);
        } else {
            Split split = findSplit(begin, end, centroids);
            const float leafCost = static_cast<float>(n);
            const float splitCost =
                split.axis < 0 ? 0.0f : mOptions.traversalCost + split.cost / std::max(box.halfArea(), 1e-30f);
            if (n <= mOptions.maxLeafSize && (split.axis < 0 || leafCost <= splitCost)) return leaf(begin, end, box);
            if (split.axis < 0) {
                mid = medianSplit(begin, end, centroids);
            } else {
                const int axis = split.axis;
                const float lo = centroids.min[axis];
                const float scale = static_cast<float>(mOptions.bins) / (centroids.max[axis] - lo);
                auto it = std::partition(mOrder.begin() + begin, mOrder.begin() + end, [&](uint32_t p) {
                    return binOf(mPrims[p].centroid[axis], lo, scale) < split.bin;
                });
                mid = static_cast<uint32_t>(it - mOrder.begin());
            }
        }

        const uint32_t index = static_cast<uint32_t>(mOut.nodes.size());
        mOut.nodes.emplace_back();
        mMaxDepth = std::max(mMaxDepth, depth);
        mCost += mOptions.traversalCost * box.halfArea() / mRootArea;
        BvhBox leftBox, leftCentroids, rightBox, rightCentroids;
        bounds(begin, mid, leftBox, leftCentroids);
        bounds(mid, end, rightBox, rightCentroids);
        BvhChild a = build(begin, mid, depth + 1, leftBox, leftCentroids);
        BvhChild b = build(mid, end, depth + 1, rightBox, rightCentroids);
        setChild(mOut.nodes[index], 0, a);
        setChild(mOut.nodes[index], 1, b);
        BvhChild c;
        c.box = box;
        c.link = index;
        c.count = 0;
        return c;
    }

    std::span<const BvhBuildTriangle> mTriangles;
    BvhBuildOptions mOptions;
    BvhArrays& mOut;
    std::vector<Prim> mPrims;
    std::vector<uint32_t> mOrder;
    std::vector<BvhBox> mBinBoxes; // scratch of findSplit, one per bin
    std::vector<uint32_t> mBinCounts;
    std::vector<float> mRightCost;
    uint32_t mMaxDepth = 0;
    float mRootArea = 1.0f;
    float mCost = 0.0f;
};

} // namespace

BvhBottomLevel buildBottomLevel(std::span<const BvhBuildTriangle> triangles, const BvhBuildOptions& options,
                                BvhArrays& out) {
    if (triangles.size() >= kNone) throw InternalError("BVH build: too many triangles for 32-bit links");
    return Builder(triangles, options, out).run();
}

namespace {

// The box of node's subtree, after writing its children's boxes from their triangles (leaves) or subtrees.
BvhBox refitNode(BvhArrays& arrays, uint32_t node) {
    BvhBox box;
    for (int which = 0; which < 2; ++which) {
        BvhChild child = childOf(arrays.nodes[node], which);
        if (child.absent()) continue;
        BvhBox b;
        if (child.leaf()) {
            for (uint32_t t = child.link; t < child.link + child.count; ++t) {
                const GpuBvhTriangle& tri = arrays.triangles[t];
                b.expand(glm::vec3(tri.v0));
                b.expand(glm::vec3(tri.v1));
                b.expand(glm::vec3(tri.v2));
            }
        } else {
            b = refitNode(arrays, child.link);
        }
        child.box = b;
        setChild(arrays.nodes[node], which, child);
        box.expand(b);
    }
    return box;
}

} // namespace

void refitBottomLevel(BvhBottomLevel& level, BvhArrays& arrays,
                      const std::function<void(const GpuBvhTriangleRef&, glm::vec3 (&)[3])>& corners) {
    for (uint32_t t = level.firstTriangle; t < level.firstTriangle + level.triangleCount; ++t) {
        glm::vec3 v[3];
        corners(arrays.refs[t], v);
        arrays.triangles[t] = {glm::vec4(v[0], 0.0f), glm::vec4(v[1], 0.0f), glm::vec4(v[2], 0.0f)};
    }
    level.bounds = refitNode(arrays, level.root);
}

} // namespace vitrine::accel
