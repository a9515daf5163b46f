// The binned SAH builder (sah_builder.hpp): binning, the SAH sweep, partitioning and the
// thread pool that builds large subtrees in parallel.
#include "bvh/sah_builder.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#include <unistd.h>
#define LUCENT_SCRATCH_MMAP 1
#endif

namespace lucent::bvh::detail {

ScratchNodes::ScratchNodes(std::size_t n) : bytes_(std::max<std::size_t>(1, n) * sizeof(Node2)) {
#ifdef LUCENT_SCRATCH_MMAP
  void* m = ::mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (m != MAP_FAILED) {
    p_ = static_cast<Node2*>(m);
    mapped_ = true;
    return;
  }
#endif
  p_ = new Node2[bytes_ / sizeof(Node2)];
}

ScratchNodes::~ScratchNodes() { free_all(); }

ScratchNodes::ScratchNodes(ScratchNodes&& o) noexcept
    : p_(o.p_), bytes_(o.bytes_), released_(o.released_), mapped_(o.mapped_) {
  o.p_ = nullptr;
}

ScratchNodes& ScratchNodes::operator=(ScratchNodes&& o) noexcept {
  if (this != &o) {
    free_all();
    p_ = o.p_, bytes_ = o.bytes_, released_ = o.released_, mapped_ = o.mapped_;
    o.p_ = nullptr;
  }
  return *this;
}

void ScratchNodes::free_all() {
  if (!p_) return;
#ifdef LUCENT_SCRATCH_MMAP
  if (mapped_) {
    ::munmap(p_, bytes_);
    p_ = nullptr;
    return;
  }
#endif
  delete[] p_;
  p_ = nullptr;
}

void ScratchNodes::release_below(std::size_t i) {
#ifdef LUCENT_SCRATCH_MMAP
  if (!mapped_) return;
  static const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  // in steps of 1 MiB or more: one system call per few thousand nodes
  const std::size_t upto = std::min(i * sizeof(Node2), bytes_) / page * page;
  if (upto < released_ + (std::size_t(1) << 20)) return;
  ::madvise(reinterpret_cast<char*>(p_) + released_, upto - released_, MADV_DONTNEED);
  released_ = upto;
#else
  (void)i;
#endif
}

namespace {

constexpr int kBins = 32;
constexpr std::size_t kSpawnSize = 2048;  // subtrees at least this large go to the shared queue
constexpr std::size_t kParallelBinSize = 1u << 17;  // nodes this large bin on every thread
constexpr unsigned kMaxDepth = LC_BVH_MAX_DEPTH;    // bounds the kernel's traversal stack

// A node to build. Scratch node slots are handed out without any shared counter: a node of k
// primitives has at most 2k - 2 descendants, so it owns the block [block, block + 2k - 2) and
// splits it exactly between its two children (pair, left block of 2a - 2, right block of 2b - 2).
struct Task {
  lc_uint node;   // index in the scratch node array
  lc_uint block;  // first slot of the block for the node's descendants
  std::size_t begin, end;
  unsigned depth;  // root: 1
  Box box;         // bounds of the primitives
  Box cbox;        // bounds of their doubled centroids
};

// Maps a doubled centroid to one bin per axis; identical in binning and partitioning. Small nodes
// use fewer bins (as many as primitives): cheaper, and no worse.
struct BinMap {
  int bins;
  V4 lo, scale;
  BinMap(const Box& cbox, std::size_t n)
      : bins(static_cast<int>(std::min<std::size_t>(kBins, std::max<std::size_t>(n, 4)))) {
    alignas(16) float l[4], h[4], s[4] = {0, 0, 0, 0};
    cbox.lo.store(l);
    cbox.hi.store(h);
    for (int a = 0; a < 3; ++a) {
      float ext = h[a] - l[a];
      s[a] = ext > 0 ? bins * (1 - 1e-6f) / ext : 0.0f;
    }
    lo = V4::xyz(l[0], l[1], l[2]);
    scale = V4::load(s);
  }
  bool usable(int a) const {
    alignas(16) float s[4];
    scale.store(s);
    return s[a] > 0;
  }
  void operator()(V4 c2, int* k) const { ((c2 - lo) * scale).bins(float(bins - 1), k); }
};

// Bins of one node; only the first n of each axis are initialised and used.
struct Bins {
  struct BinBox {  // trivially constructible
    V4 lo, hi;
  };
  int n;
  BinBox box[3][kBins];
  lc_uint count[3][kBins];
  lc_uint spheres[3][kBins];  // how many of count are spheres
  explicit Bins(int bins) : n(bins) {
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < n; ++k) {
        box[a][k] = {V4::splat(INFINITY), V4::splat(-INFINITY)};
        count[a][k] = 0;
        spheres[a][k] = 0;
      }
  }
  void grow(int a, int k, V4 lo, V4 hi, lc_uint sphere) {
    box[a][k].lo = vmin(box[a][k].lo, lo);
    box[a][k].hi = vmax(box[a][k].hi, hi);
    ++count[a][k];
    spheres[a][k] += sphere;
  }
  void add(const Bins& o) {
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < n; ++k) {
        box[a][k].lo = vmin(box[a][k].lo, o.box[a][k].lo);
        box[a][k].hi = vmax(box[a][k].hi, o.box[a][k].hi);
        count[a][k] += o.count[a][k];
        spheres[a][k] += o.spheres[a][k];
      }
  }
};

// count_spheres: also count the spheres per bin (only needed when the scene has some)
void bin_range(const PrimRef* refs, std::size_t n, const BinMap& map, Bins& bins,
               bool count_spheres) {
  alignas(16) int k[4];
  for (std::size_t i = 0; i < n; ++i) {
    const PrimRef& p = refs[i];
    map(p.centroid2(), k);
    lc_uint sphere = count_spheres ? p.id() >> 31 : 0;  // LC_PRIM_SPHERE_BIT
    for (int a = 0; a < 3; ++a) bins.grow(a, k[a], p.lo, p.hi, sphere);
  }
}

unsigned ceil_log2(std::size_t n) {
  unsigned l = 0;
  while ((std::size_t(1) << l) < n) ++l;
  return l;
}

class Builder {
 public:
  Builder(std::vector<PrimRef>& refs, const BuildOptions& options, unsigned threads,
          bool has_spheres)
      : refs_(refs),
        has_spheres_(has_spheres),
        max_leaf_(static_cast<std::size_t>(std::max(1, options.max_leaf_size))),
        threads_(threads),
        traversal_cost_(options.traversal_cost),
        block_(static_cast<std::size_t>(std::max(1, options.leaf_block))) {
    nodes_ = ScratchNodes(2 * refs.size() - 1);
  }

  // Builds the tree over refs_, whose bounds and centroid bounds are given; returns the number
  // of scratch nodes.
  std::size_t run(const Box& box, const Box& cbox) {
    Task root{0, 1, 0, refs_.size(), 1, box, cbox};
    queue_.push_back(root);
    pending_ = 1;
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < threads_; ++i) pool.emplace_back([this] { worker(); });
    worker();
    for (auto& t : pool) t.join();
    return 1 + 2 * interior_.load();
  }

  ScratchNodes release_nodes() { return std::move(nodes_); }

  // intersection cost of n primitives of which s spheres: the kernel tests the triangles by
  // blocks of block_, the spheres one by one
  float cost(std::size_t n, std::size_t s) const {
    return float((n - s + block_ - 1) / block_ + s);
  }
  std::size_t max_depth() const { return max_depth_.load(); }

 private:
  void worker() {
    for (;;) {
      Task t;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return !queue_.empty() || pending_ == 0; });
        if (queue_.empty()) return;
        t = queue_.back();
        queue_.pop_back();
      }
      build_subtree(t);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (--pending_ == 0) cv_.notify_all();
      }
    }
  }

  void spawn(const Task& t) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(t);
      ++pending_;
    }
    cv_.notify_one();
  }

  void make_leaf(const Task& t) {
    Node2& n = nodes_[t.node];
    n.left_first = static_cast<lc_uint>(t.begin);
    n.count = static_cast<lc_uint>(t.end - t.begin);
    std::size_t d = max_depth_.load(std::memory_order_relaxed);
    while (t.depth > d && !max_depth_.compare_exchange_weak(d, t.depth)) {
    }
  }

  // Bins the task's primitives; big nodes bin on helper threads too while no other task runs.
  void bin(const Task& t, const BinMap& map, Bins& bins) {
    std::size_t n = t.end - t.begin;
    unsigned parts = 1;
    if (n >= kParallelBinSize && threads_ > 1) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pending_ == 1) parts = threads_;  // the other workers are idle (near the root)
    }
    if (parts <= 1) {
      bin_range(refs_.data() + t.begin, n, map, bins, has_spheres_);
      return;
    }
    std::vector<Bins> partial(parts - 1, Bins(map.bins));
    std::vector<std::thread> helpers;
    std::size_t step = (n + parts - 1) / parts;
    for (unsigned p = 1; p < parts; ++p) {
      std::size_t b = std::min(n, p * step), e = std::min(n, (p + 1) * step);
      helpers.emplace_back([&, b, e, p] {
        bin_range(refs_.data() + t.begin + b, e - b, map, partial[p - 1], has_spheres_);
      });
    }
    bin_range(refs_.data() + t.begin, std::min(n, step), map, bins, has_spheres_);
    for (auto& h : helpers) h.join();
    for (auto& p : partial) bins.add(p);
  }

  // Splits at the object median along the widest axis (the depth guard and equal centroids).
  std::size_t median_split(const Task& t, Task& l, Task& r) {
    int axis = 0;
    alignas(16) float ext[4];
    (t.cbox.hi - t.cbox.lo).store(ext);
    for (int a = 1; a < 3; ++a)
      if (ext[a] > ext[axis]) axis = a;
    std::size_t mid = t.begin + (t.end - t.begin) / 2;
    if (ext[axis] > 0)
      std::nth_element(refs_.begin() + t.begin, refs_.begin() + mid, refs_.begin() + t.end,
                       [axis](const PrimRef& x, const PrimRef& y) {
                         alignas(16) float cx[4], cy[4];
                         x.centroid2().store(cx);
                         y.centroid2().store(cy);
                         return cx[axis] < cy[axis];
                       });
    for (std::size_t i = t.begin; i < t.end; ++i) {
      Task& side = i < mid ? l : r;
      side.box.grow(refs_[i].lo, refs_[i].hi);
      side.cbox.grow_point(refs_[i].centroid2());
    }
    return mid;
  }

  void build_subtree(Task root) {
    std::vector<Task> stack{root};
    std::size_t interior = 0;
    while (!stack.empty()) {
      Task t = stack.back();
      stack.pop_back();
      Node2& node = nodes_[t.node];
      t.box.get(node.bmin, node.bmax);
      std::size_t n = t.end - t.begin;
      if (n == 1) {
        make_leaf(t);
        continue;
      }
      float cext = t.cbox.max_extent();
      Task l{0, 0, t.begin, 0, t.depth + 1, {}, {}}, r{0, 0, 0, t.end, t.depth + 1, {}, {}};
      std::size_t mid;
      bool guard = t.depth + ceil_log2((n + max_leaf_ - 1) / max_leaf_) + 1 >= kMaxDepth;
      if (!(cext > 0) || guard) {
        if (n <= max_leaf_) {
          make_leaf(t);
          continue;
        }
        mid = median_split(t, l, r);
      } else {
        BinMap map(t.cbox, n);
        Bins bins(map.bins);
        bin(t, map, bins);
        // sweep: right-to-left areas, then left-to-right with the SAH
        float best = INFINITY;
        int best_axis = -1, best_k = 0;
        std::size_t node_spheres = 0;  // every primitive is in one bin of each axis
        for (int k = 0; k < map.bins; ++k) node_spheres += bins.spheres[0][k];
        for (int a = 0; a < 3; ++a) {
          if (!map.usable(a)) continue;
          const int nb = map.bins;
          float right_area[kBins];
          std::size_t right_count[kBins], right_spheres[kBins];
          Box acc;
          std::size_t cnt = 0, sph = 0;
          for (int k = nb - 1; k > 0; --k) {
            acc.grow(bins.box[a][k].lo, bins.box[a][k].hi);
            cnt += bins.count[a][k];
            sph += bins.spheres[a][k];
            right_area[k] = acc.area();
            right_count[k] = cnt;
            right_spheres[k] = sph;
          }
          Box lacc;
          std::size_t lcnt = 0, lsph = 0;
          for (int k = 1; k < nb; ++k) {
            lacc.grow(bins.box[a][k - 1].lo, bins.box[a][k - 1].hi);
            lcnt += bins.count[a][k - 1];
            lsph += bins.spheres[a][k - 1];
            if (lcnt == 0 || right_count[k] == 0) continue;
            float c = lacc.area() * cost(lcnt, lsph) +
                      right_area[k] * cost(right_count[k], right_spheres[k]);
            if (c < best) {
              best = c;
              best_axis = a;
              best_k = k;
            }
          }
        }
        float area = t.box.area();
        float split_cost = traversal_cost_ * area + best;  // both scaled by the node's area
        float leaf_cost = cost(n, node_spheres) * area;
        if (n <= max_leaf_ && (best_axis < 0 || leaf_cost <= split_cost)) {
          make_leaf(t);
          continue;
        }
        if (best_axis < 0) {
          mid = median_split(t, l, r);
        } else {
          // partition, growing the children's bounds on the way
          std::size_t i = t.begin, j = t.end;
          const int a = best_axis;
          alignas(16) int k[4];
          while (i < j) {
            V4 c = refs_[i].centroid2();
            map(c, k);
            if (k[a] < best_k) {
              l.box.grow(refs_[i].lo, refs_[i].hi);
              l.cbox.grow_point(c);
              ++i;
            } else {
              --j;
              r.box.grow(refs_[i].lo, refs_[i].hi);
              r.cbox.grow_point(c);
              std::swap(refs_[i], refs_[j]);
            }
          }
          mid = i;
        }
      }
      l.end = mid;
      r.begin = mid;
      lc_uint left = t.block;
      ++interior;
      node.left_first = left;
      node.count = 0;
      l.node = left;
      r.node = left + 1;
      l.block = left + 2;
      r.block = static_cast<lc_uint>(left + 2 * (l.end - l.begin));
      // the larger child continues here, the other goes to the pool when it is big enough
      Task& big = (l.end - l.begin) >= (r.end - r.begin) ? l : r;
      Task& small = &big == &l ? r : l;
      if (threads_ > 1 && small.end - small.begin >= kSpawnSize)
        spawn(small);
      else
        stack.push_back(small);
      stack.push_back(big);
    }
    interior_ += interior;
  }

  std::vector<PrimRef>& refs_;
  bool has_spheres_;
  std::size_t max_leaf_;
  unsigned threads_;
  float traversal_cost_;
  std::size_t block_;
  ScratchNodes nodes_;  // scratch tree (2n - 1 slots, not zeroed)
  std::atomic<std::size_t> interior_{0};
  std::atomic<std::size_t> max_depth_{0};
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Task> queue_;
  std::size_t pending_ = 0;
};

}  // namespace

ScratchTree build_sah_tree(std::vector<PrimRef>& refs, const Box& box, const Box& cbox,
                           const BuildOptions& options, unsigned threads, bool has_spheres) {
  Builder builder(refs, options, threads, has_spheres);
  ScratchTree t;
  t.count = builder.run(box, cbox);
  t.max_depth = builder.max_depth();
  t.nodes = builder.release_nodes();
  return t;
}

}  // namespace lucent::bvh::detail
