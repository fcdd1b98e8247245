// What a traversal did, counted per ray: the nodes whose children it tested, the leaf packs it
// tested and the triangles in them. The kernels take a counter policy: NoCount compiles to
// nothing (the default renders), CountInto adds to a TraversalCounts (--count), so counting costs
// nothing when off and is one instantiation of each kernel when on.
#pragma once

#include <atomic>
#include <cstdint>

namespace tracer {

struct TraversalCounts {
  uint64_t rays = 0, nodes = 0, packs = 0, triangles = 0;
  TraversalCounts& operator+=(const TraversalCounts& o) {
    rays += o.rays;
    nodes += o.nodes;
    packs += o.packs;
    triangles += o.triangles;
    return *this;
  }
  bool operator==(const TraversalCounts&) const = default;
};

// By kind of query: closest hit (camera, reflected and path rays) and any hit (shadow and AO rays).
struct QueryCounts {
  TraversalCounts closest, any;
  QueryCounts& operator+=(const QueryCounts& o) {
    closest += o.closest;
    any += o.any;
    return *this;
  }
};

// Per-tile counts summed across workers (one atomic add per field per tile, never per ray).
struct AtomicQueryCounts {
  std::atomic<uint64_t> v[8] = {};
  void add(const QueryCounts& c) {
    const uint64_t f[8] = {c.closest.rays, c.closest.nodes, c.closest.packs, c.closest.triangles,
                           c.any.rays,     c.any.nodes,     c.any.packs,     c.any.triangles};
    for (int i = 0; i < 8; ++i) v[i].fetch_add(f[i], std::memory_order_relaxed);
  }
  QueryCounts load() const {
    QueryCounts c;
    c.closest = {v[0].load(), v[1].load(), v[2].load(), v[3].load()};
    c.any = {v[4].load(), v[5].load(), v[6].load(), v[7].load()};
    return c;
  }
};

// The kernels' counter policies. `lanes`: how many rays (a packet's or bundle's) the step is for.
struct NoCount {
  void rays(uint32_t) const {}
  void node(uint32_t) const {}
  void pack(uint32_t, uint32_t) const {}
};
struct CountInto {
  TraversalCounts* counts;
  void rays(uint32_t lanes) const { counts->rays += lanes; }
  void node(uint32_t lanes) const { counts->nodes += lanes; }
  void pack(uint32_t lanes, uint32_t triangles) const {
    counts->packs += lanes;
    counts->triangles += uint64_t(lanes) * triangles;
  }
};

}  // namespace tracer
