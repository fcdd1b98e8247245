#include <algorithm>
#include <sstream>

#include "accel/builders/wide_tree_build.hpp"
#include "accel/two_level/two_level_bvh.hpp"

namespace tracer {

namespace {

// Meshes this large are built one at a time with every thread; smaller ones side by side, each
// by one thread (a tree of a few thousand triangles is not worth forking).
constexpr uint32_t kParallelMesh = 65536;

}  // namespace

TwoLevelBvh::TwoLevelBvh(const Scene& scene, const BvhBuildOptions& options)
    : TwoLevelBvh(scene, options, Executor(options.strategy, options.threads)) {}

TwoLevelBvh::TwoLevelBvh(const Scene& scene, const BvhBuildOptions& options, const Executor& exec)
    : scene_(&scene), simd_(SimdDispatch::of(options.simd)) {
  meshes_.resize(scene.meshes.size());
  const Executor one(Strategy::Seq, 1);
  std::vector<uint32_t> small;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    if (scene.meshes[m].triangles.count >= kParallelMesh) {
      meshes_[m] = std::make_unique<WideBvh>(scene, scene.meshes[m].triangles, options, exec);
    } else {
      small.push_back(m);
    }
  }
  exec.run([&] {
    exec.for_each(small.size(), [&](size_t k) {
      const uint32_t m = small[k];
      meshes_[m] = std::make_unique<WideBvh>(scene, scene.meshes[m].triangles, options, one);
    });
  });
  throw_if_cancelled(options.cancel);
  // The top level: each instance's world box, one per leaf.
  std::vector<Aabb> boxes(scene.instances.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Instance& in = scene.instances[i];
    boxes[i] = meshes_[in.mesh]->nodes().empty() ? Aabb{} : in.bounds;
  }
  BvhBuildOptions top = options;
  top.max_leaf = 1;
  top.split_budget = 0.0f;
  exec.run([&] {
    PrimSplitter splitter(std::span<const Aabb>(boxes), top, exec);
    std::vector<LeafRun> runs;
    build_wide_tree(splitter, top, exec, 1, top_, runs);
    for (WideNode& n : top_) {
      for (int c = 0; c < kWideWidth; ++c) {
        if (n.count[c] != 0) n.child[c] = splitter.refs()[runs[n.child[c]].first].id();
      }
    }
  });
}

size_t TwoLevelBvh::memory_bytes() const {
  size_t bytes = top_.size() * sizeof(WideNode);
  for (const auto& m : meshes_) bytes += m->memory_bytes();
  return bytes;
}

std::string TwoLevelBvh::validate() const {
  std::vector<int> seen(scene_->instances.size(), 0);
  std::ostringstream err;
  const auto check = [&](uint32_t node, const Aabb& box, auto& self) -> void {
    const WideNode& n = top_[node];
    for (int c = 0; c < kWideWidth; ++c) {
      if (n.lo_x[c] > n.hi_x[c]) continue;
      const Aabb child{{n.lo_x[c], n.lo_y[c], n.lo_z[c]}, {n.hi_x[c], n.hi_y[c], n.hi_z[c]}};
      if (!box.empty() && !(box.contains(child))) err << "top node " << node << " child " << c << " leaves its box; ";
      if (n.count[c] != 0) {
        const uint32_t i = n.child[c];
        if (i >= seen.size()) {
          err << "top leaf names instance " << i << "; ";
          continue;
        }
        ++seen[i];
        if (!child.contains(scene_->instances[i].bounds)) err << "instance " << i << " leaves its leaf box; ";
      } else {
        self(n.child[c], child, self);
      }
    }
  };
  if (!top_.empty()) check(0, Aabb{}, check);
  for (size_t i = 0; i < seen.size(); ++i) {
    const bool placed = !meshes_[scene_->instances[i].mesh]->nodes().empty();
    if (seen[i] != (placed ? 1 : 0)) err << "instance " << i << " is in " << seen[i] << " leaves; ";
  }
  for (size_t m = 0; m < meshes_.size(); ++m) {
    if (std::string e = meshes_[m]->validate(); !e.empty()) err << "mesh " << m << ": " << e << "; ";
  }
  return err.str();
}

}  // namespace tracer
