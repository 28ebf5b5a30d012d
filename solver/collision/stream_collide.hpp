// The fused collide-and-push kernel of one block (thesis eq. 2.1 and 2.23), in place.
//
// One pass over the interior: read the Q shifted populations of a node (pre-collision,
// time t), compute ρ and u (with half the force when forced), the equilibrium, collide, and
// write the post-collision values back into the node's own Q slots, where the next step finds
// them as its neighbours' populations (the AA pattern, field/populations.hpp). Pushes that
// leave the interior land in ghost slots, where the boundary stages pick them up; populations
// entering the interior from outside are written by those stages after the sweep.
// The force term is compiled away for unforced blocks (Forced = false).
// Rows (x lines) are distributed over OpenMP threads; the x loop is straight-line code.
#pragma once

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <vector>

#include "collision/equilibrium.hpp"
#include "collision/operators.hpp"
#include "field/grid.hpp"
#include "field/populations.hpp"

namespace caplab::collision {

/// Visits all interior rows (x lines) of a grid in parallel: f(row_base, index of the row's
/// first node).
template <int D, class F>
void parallel_rows(const field::Grid<D>& g, F&& f) {
  const int ny = g.n()[1];
  const int nz = D == 3 ? g.n()[D - 1] : 1;
  const long rows = static_cast<long>(ny) * nz;
#pragma omp parallel for schedule(static)
  for (long r = 0; r < rows; ++r) {
    Index<D> ijk{};
    ijk[1] = static_cast<int>(r % ny);
    if constexpr (D == 3) ijk[2] = static_cast<int>(r / ny);
    f(g.index(ijk), ijk);
  }
}

/// Guo-forced collision of one node (thesis eq. 2.23-2.25 with the force term of eq. 5.22).
template <class L, class T, class Op>
inline void collide_forced(const T (&f)[L::q], const T (&F)[L::d], const Op& op, T (&out)[L::q]) {
  T rho, u[L::d], feq[L::q], s[L::q];
  moments<L, T>(f, F, rho, u);
  equilibrium<L, T>(rho, u, feq);
  guo_source<L, T>(u, F, s);
  op.template collide<L, T>(f, feq, s, out);
}

/// Nodes per vector chunk of the fused kernel: one 64-byte cache line of one population.
template <class T>
inline constexpr int simd_chunk = static_cast<int>(64 / sizeof(T));

/// Cache lines ahead that the fused kernel prefetches on each of its Q streams. The hardware
/// prefetchers do not keep up with 19 read and 19 write streams: measured on one thread
/// (harness of the kernel alone, 128^3, D3Q19 BGK, AMD Zen 5, 2026-12-04, A–B pattern),
/// double 60 -> 98 MLUPS and single 106 -> 198 with 6 lines; 4 to 10 lines are all within
/// 5 % of that.
inline constexpr int prefetch_lines = 6;

/// Prefetches, for writing, population i of node n for every i: the slots the kernel reads
/// and writes back prefetch_lines chunks later.
template <int Q, class T>
[[gnu::always_inline]] inline void prefetch_node(T* const (&P)[Q], std::ptrdiff_t n) {
#pragma GCC unroll 19
  for (int i = 0; i < Q; ++i) __builtin_prefetch(P[i] + n, 1, 3);
}

/// The fused kernel's collision of one node's populations f (Guo-forced with F when Forced;
/// F is not read otherwise). Also the band's step of a two-level coupling
/// (refinement/two_level.hpp), which must collide exactly as the sweep would.
template <bool Forced, class L, class T, class Op>
[[gnu::always_inline]] inline void collide_node(const T (&f)[L::q], const T (&F)[L::d], const Op& op,
                                                T (&out)[L::q]) {
  if constexpr (Forced) {
    collide_forced<L, T>(f, F, op, out);
  } else {
    T rho, u[L::d], feq[L::q];
    moments<L, T>(f, rho, u);
    equilibrium<L, T>(rho, u, feq);
    op.template collide<L, T>(f, feq, out);
  }
}

/// The velocity u + F/(2ρ) of a node's populations f under the force F, in double (thesis
/// eq. 2.25: what the forced collision uses and the IB's markers move with), as up[a][n].
template <class L, class T>
[[gnu::always_inline]] inline void store_forced_velocity(const T (&f)[L::q], const double* const (&fp)[L::d],
                                                         double* const* up, std::ptrdiff_t n, bool store = true) {
  double fd[L::q], rho, j[L::d];
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i) fd[i] = f[i];
  density_momentum<L, double>(fd, rho, j);
  const double inv_rho = 1.0 / rho;
  // An explicit fma: GCC contracts j * inv_rho + ... or not depending on the code around it,
  // and the sweep's velocity must equal forced_velocity_at's bit for bit.
  if (store)
    for (int a = 0; a < L::d; ++a) up[a][n] = std::fma(j[a], inv_rho, fp[a][n] / (2.0 * rho));
}

/// Collide-and-push of node n in place (the body of the fused kernel's vector loop): reads
/// f_i from P[i][n], writes the post-collision value i to P[ī][n] (field/populations.hpp: the
/// same Q slots, and where the next step at the other parity finds it at node n + c_i).
/// With Velocity (forced only), also the node's velocity before the collision into up
/// (store_forced_velocity). Scalars and references to C arrays only, so that GCC vectorizes
/// the loop that calls it. With `store` false the node is computed and nothing is written
/// (the idle lanes of update_tail).
template <bool Forced, class L, class T, bool Velocity = false, class Op>
[[gnu::always_inline]] inline void update_node(T* const (&P)[L::q], const Op& op, const double* const (&fp)[L::d],
                                               std::ptrdiff_t n, double* const* up = nullptr, bool store = true) {
  static_assert(Forced || !Velocity, "the velocity with the force is the forced kernel's");
  constexpr int Q = L::q, D = L::d;
  T f[Q], F[D], out[Q];
#pragma GCC unroll 19
  for (int i = 0; i < Q; ++i) f[i] = P[i][n];
  if constexpr (Velocity) store_forced_velocity<L, T>(f, fp, up, n, store);
  if constexpr (Forced)
    for (int a = 0; a < D; ++a) F[a] = T(fp[a][n]);
  collide_node<Forced, L, T>(f, F, op, out);
  if (store)
#pragma GCC unroll 19
    for (int i = 0; i < Q; ++i) P[L::opposite[i]][n] = out[i];
}

/// Updates the `rem` (< 2w) nodes from `at` as pieces of w, w/2, …, 1 consecutive nodes, each a
/// vector loop of a trip count known at compile time: the end of a row without overlapping
/// chunks. Out of line and flattened: inlined into the row loop, GCC 12 ran out of inlining
/// budget, called the collision out of line and left the pieces scalar.
template <int w, bool Forced, class L, class T, bool Velocity = false, class Op>
[[gnu::noinline, gnu::flatten]] void update_pieces(T* const (&P)[L::q], const Op& op, const double* const (&fp)[L::d],
                                                 std::ptrdiff_t at, int rem, double* const* up = nullptr) {
  if constexpr (w >= 1) {
    if (rem & w) {
      const Op op_l = op;  // as in update_run
#pragma omp simd
      for (int x = 0; x < w; ++x) update_node<Forced, L, T, Velocity>(P, op_l, fp, at + x, up);
      at += w;
    }
    update_pieces<w / 2, Forced, L, T, Velocity>(P, op, fp, at, rem, up);
  }
}

/// Updates the `rem` (< W) nodes from `at` as one vector chunk of W lanes whose lanes from `rem`
/// on load and compute but store nothing (masked stores). Their loads reach the next W − rem
/// nodes of the buffer (the ghost layer or the next row; inside the buffer): values that are
/// discarded, whoever updates those nodes. Out of line and flattened, as update_pieces.
template <bool Forced, class L, class T, bool Velocity = false, class Op>
[[gnu::noinline, gnu::flatten]] void update_tail(T* const (&P)[L::q], const Op& op, const double* const (&fp)[L::d],
                                               std::ptrdiff_t at, int rem, double* const* up = nullptr) {
  constexpr int W = simd_chunk<T>;
  const Op op_l = op;  // as in update_run
#pragma omp simd
  for (int x = 0; x < W; ++x) update_node<Forced, L, T, Velocity>(P, op_l, fp, at + x, up, x < rem);
}

/// The first x of the fused kernel's row runs (the x0 of sweep) on a block of nx nodes per row
/// whose ghost layer nothing reads: −1 where the ghost before each row makes the runs whole
/// chunks (nx + 1 a multiple of simd_chunk<T>, as for fine blocks of 47 or 127 nodes), else 0.
/// Updating a ghost writes only the slots it owns (field/populations.hpp): those that enter the
/// interior, which the stage after the sweep overwrites (the two-level fill), and slots of the
/// ghost layer, which no interior node reads. The ghost's values are not a flow state and may
/// grow without bound; nothing reads them. Measured on the 128^3 bench box's 127^3 fine block:
/// solver/bench/NOTES.md, "The fine rows start at their ghost".
template <class T>
constexpr int ghost_row_start(int nx) {
  return (nx + 1) % simd_chunk<T> == 0 ? -1 : 0;
}

/// Updates the n consecutive nodes from `at`: whole vector chunks, prefetching ahead, then the
/// rest: in single precision (16 lanes) one masked chunk (update_tail), in double (8 lanes)
/// pieces (update_pieces). Measured, the rate of an n^3 periodic box over that of an (n + 1)^3
/// box in the same process, D3Q19 BGK, 2 threads, AMD EPYC (solver/bench/NOTES.md, "The row's
/// end"): single 47^3 0.65 with pieces, 0.85-0.95 masked; 127^3 0.79-0.81 -> 0.94-0.96; double
/// 47^3 0.85-0.86 with pieces, 0.69-0.70 masked. Pieces of 8, 4, 2, 1 float lanes are four
/// passes, down to scalar code; of 4, 2, 1 double lanes about one chunk's work.
template <bool Forced, class L, class T, bool Velocity = false, class Op>
[[gnu::always_inline]] inline void update_run(T* const (&P)[L::q], const Op& op, const double* const (&fp)[L::d],
                                              std::ptrdiff_t at, int n, double* const* up = nullptr) {
  constexpr int W = simd_chunk<T>;
  const int whole = n - n % W;
  // A copy in registers: through the reference, the stores through P might alias op's members,
  // and with more than a few of them (TrtBulk) GCC 12 gave up vectorizing the loop.
  const Op op_l = op;
  for (int x0 = 0; x0 < whole; x0 += W) {
    const std::ptrdiff_t chunk = at + x0;
    // Past the run's end this reaches the next rows, contiguous in memory (x fastest), which
    // this thread takes next under the static schedule; past the array's end it is harmless.
    prefetch_node<L::q>(P, chunk + prefetch_lines * W);
#pragma omp simd
    for (int x = 0; x < W; ++x) update_node<Forced, L, T, Velocity>(P, op_l, fp, chunk + x, up);
  }
  if constexpr (W >= 16) {
    if (whole < n) update_tail<Forced, L, T, Velocity>(P, op, fp, at + whole, n - whole, up);
  } else {
    update_pieces<W / 2, Forced, L, T, Velocity>(P, op, fp, at + whole, n - whole, up);
  }
}

/// The in-place sweep of one time step over the interior of a block, without the parity flip
/// (stream_collide and stream_collide_forced_at flip it). The nodes of `skip` are left alone
/// (their slots keep their values; no other node reads or writes them, field/populations.hpp).
///
/// Each row runs in chunks of simd_chunk<T> nodes with a trip count known at compile time, so
/// the whole row is vector code, and the rest of the row in pieces of half, a quarter … of a
/// chunk (update_pieces) or as one masked chunk (update_tail; see update_run). (A row of 47
/// nodes, the fine block of a chapter 5 sphere, otherwise ends in a 15-node scalar remainder:
/// measured 51 MLUPS at 47^3 against 128 at 48^3, D3Q19 TRT single, 2 threads, A–B pattern.)
/// The A–B kernel instead redid a few nodes in a last chunk shifted back to end at the row's
/// end; in place a node must not be updated twice, and the shifted chunk with the overlapping
/// lanes blended back was slow: its loads partly overlap the stores of the chunk before
/// (measured 47^3 D3Q19 BGK, 2 threads: double 136, float 106 MLUPS against 208 / 353 at 48^3;
/// with the shifted chunk first, 87 / 59).
///
/// With x0 = −1 each row's run starts at the ghost before the row (see ghost_row_start).
template <bool Forced, class L, class T, class Op>
void sweep(field::Populations<L, T>& pop, const Op& op, const field::VectorField<L::d, double>* force,
           const field::Box<L::d>& skip = {}, int x0 = 0) {
  constexpr int Q = L::q, D = L::d;
  const auto& g = pop.grid();
  const std::array<T*, Q> P = pop.bases();
  std::array<const double*, D> fp{};
  if constexpr (Forced)
    for (int a = 0; a < D; ++a) fp[a] = force->comp[a].data();
  const int nx = g.n()[0];

  parallel_rows<D>(g, [&](std::ptrdiff_t base, const Index<D>& row) {
    // Loop invariants in locals: read through the closure they are reloaded every iteration
    // and GCC does not vectorize the loop (measured: D3Q19 double 42 -> 94 MLUPS, 2 threads).
    T* P_l[Q];
    for (int i = 0; i < Q; ++i) P_l[i] = P[i];
    const Op op_l = op;
    const double* fp_l[D];
    for (int a = 0; a < D; ++a) fp_l[a] = fp[a];
    if (skip.crosses_row(row)) {
      update_run<Forced, L, T>(P_l, op_l, fp_l, base + x0, skip.lo[0] - x0);
      update_run<Forced, L, T>(P_l, op_l, fp_l, base + skip.hi[0], nx - skip.hi[0]);
    } else {
      update_run<Forced, L, T>(P_l, op_l, fp_l, base + x0, nx - x0);
    }
  });
}

/// One time step of the fluid on a block, in place: collide and push every interior node, then
/// flip the parity. Populations entering the interior from the ghost layer are left to the
/// boundary stages, which run after it (they address the new parity).
/// `force` (lattice units, per node) must be non-null exactly when Forced is true.
template <bool Forced, class L, class T, class Op>
void stream_collide(field::Populations<L, T>& pop, const Op& op,
                    const field::VectorField<L::d, double>* force = nullptr, const field::Box<L::d>& skip = {},
                    int x0 = 0) {
  sweep<Forced>(pop, op, force, skip, x0);
  pop.flip_parity();
}

/// Runs body(k) for every k in [0, count): whole chunks of W consecutive k as one `omp simd`
/// loop each (vector code: body gathers and scatters through the node list), the chunks in
/// parallel, then the rest as one chunk shifted back to end at count − 1, after the parallel
/// loop. That chunk redoes indices of the last whole chunk, so body(k) must write the same
/// values each time and nothing that another k reads. Mark a lambda body
/// `__attribute__((always_inline))`: GCC 12 otherwise calls a body as heavy as a node's moments
/// out of line and leaves the chunk loop scalar.
template <int W, class Body>
[[gnu::always_inline]] inline void for_each_in_chunks(std::ptrdiff_t count, const Body& body) {
  if (count < W) {
    for (std::ptrdiff_t k = 0; k < count; ++k) body(k);
    return;
  }
  const std::ptrdiff_t whole = count / W * W;
#pragma omp parallel for schedule(static) if (count > 256)
  for (std::ptrdiff_t k0 = 0; k0 < whole; k0 += W) {
#pragma omp simd
    for (int j = 0; j < W; ++j) body(k0 + j);
  }
  if (whole < count) {
    const std::ptrdiff_t last = count - W;
#pragma omp simd
    for (int j = 0; j < W; ++j) body(last + j);
  }
}

/// Consecutive linear indices [begin, end) inside one row's interior, at least one chunk long.
struct NodeSpan {
  std::ptrdiff_t begin, end;
};

/// The nodes a forcing stage visits: distinct interior nodes in memory order and, where the
/// block's rows are at least a vector chunk long, the spans that cover them (cover_with_spans).
/// `velocity`, when set (a block-sized field per component, D of them), asks the forced
/// collision for u + F/(2ρ) at the nodes it visits (store_forced_velocity; stale elsewhere).
struct ForcedRegion {
  std::span<const std::ptrdiff_t> nodes;
  std::span<const NodeSpan> spans;
  std::array<double*, 3> velocity{};
  bool empty() const { return nodes.empty(); }
  bool wants_velocity() const { return velocity[0] != nullptr; }
};

/// Covers the sorted distinct interior nodes `nodes` of grid g with spans of at least W nodes,
/// so that a stage over them runs as contiguous vector code, not gathers and scatters (the
/// union of the IB stencils is mostly short stretches of rows: the gathers and scatters of the
/// forced collision cost it 18 % of a chapter 6 biconcave step, solver/bench/NOTES.md).
/// Nodes of one row less than 2W apart share a span (the nodes between are visited too); a
/// span shorter than W grows to W inside its row, backwards at the row's end. Spans are
/// disjoint: two spans of one row are at least 2W − 1 apart before growing and each grows by
/// less than W. Leaves `spans` empty when the rows are shorter than W. W is the walker's chunk
/// (for_each_in_spans<W>, a span shorter than it would be overrun): both take it at compile
/// time, simd_chunk<T> of the populations.
template <int W, int D>
void cover_with_spans(const field::Grid<D>& g, std::span<const std::ptrdiff_t> nodes, std::vector<NodeSpan>& spans) {
  spans.clear();
  const int nx = g.n()[0];
  if (nx < W) return;
  const std::ptrdiff_t row = g.stride(1);  // index(x, ...) = x + 1 + (multiples of row)
  for (std::size_t k = 0; k < nodes.size();) {
    std::ptrdiff_t begin = nodes[k];
    const std::ptrdiff_t row_lo = begin - begin % row + 1, row_hi = row_lo + nx;
    std::ptrdiff_t end = begin + 1;
    for (++k; k < nodes.size() && nodes[k] < row_hi && nodes[k] - end < 2 * W; ++k) end = nodes[k] + 1;
    if (end - begin < W) {
      begin = std::min(begin, row_hi - W);
      end = begin + W;
    }
    spans.push_back({begin, end});
  }
}

/// Runs body(n) for every node n of the spans (cover_with_spans<W>): each span as whole chunks
/// of W consecutive nodes, one `omp simd` loop each, the last shifted back to end at the span's
/// end (it redoes nodes, so body must write the same values each time and nothing another node
/// reads); the spans in parallel (they are disjoint).
template <int W, class Body>
[[gnu::always_inline]] inline void for_each_in_spans(std::span<const NodeSpan> spans, const Body& body) {
  const auto count = static_cast<std::ptrdiff_t>(spans.size());
#pragma omp parallel for schedule(static) if (count > 64)
  for (std::ptrdiff_t s = 0; s < count; ++s) {
    const NodeSpan span = spans[s];
    for (std::ptrdiff_t c0 = span.begin; c0 < span.end; c0 += W) {
      const std::ptrdiff_t c = std::min(c0, span.end - W);
#pragma omp simd
      for (int j = 0; j < W; ++j) body(c + j);
    }
  }
}

/// body(n) for the nodes of `region`: over its spans where it has them, otherwise over the
/// node list (for_each_in_chunks, gathers and scatters).
template <int W, class Body>
[[gnu::always_inline]] inline void for_each_forced_node(const ForcedRegion& region, const Body& body) {
  if (!region.spans.empty()) {
    for_each_in_spans<W>(region.spans, body);
    return;
  }
  const std::ptrdiff_t* node = region.nodes.data();
  auto listed = [&](std::ptrdiff_t k) __attribute__((always_inline)) { body(node[k]); };
  for_each_in_chunks<W>(static_cast<std::ptrdiff_t>(region.nodes.size()), listed);
}

/// update_run as a call (noinline, flattened): a row cut into stretches calls it several times,
/// and inlined so often into the row loop GCC 12 would run out of inlining budget and leave the
/// collision out of line (see update_pieces).
template <bool Forced, class L, class T, bool Velocity = false, class Op>
[[gnu::noinline, gnu::flatten]] void update_stretch(T* const (&P)[L::q], const Op& op,
                                                  const double* const (&fp)[L::d], std::ptrdiff_t at, int n,
                                                  double* const* up = nullptr) {
  update_run<Forced, L, T, Velocity>(P, op, fp, at, n, up);
}

/// One time step of a block with Guo forcing at the nodes of `region` only (the force must be
/// zero off region.nodes; the nodes between them that its spans visit take the forced update
/// with zero force: the unforced one up to round-off), then the parity flip. This keeps the
/// forced kernel, about twice the cost per node, to the IB's stencils. One sweep: each row runs
/// the region's stretches in it (its spans, or its listed nodes one by one where the rows are
/// too short for spans) with the forced kernel and the rest with the unforced one, so every
/// node is updated once, in place. Where the region asks for it, the forced stretches also
/// write the velocity before the collision (region.velocity: what forced_velocity_at would
/// give, without its pass over the populations, which was 4 % of a chapter 5 sphere's
/// samples, solver/bench/NOTES.md). (Before, the region was collided into scratch ahead of an
/// unforced sweep of the whole block and copied over its results: with the region's nodes
/// swept twice and the copy, 9 % of a chapter 5 sphere's step, solver/bench/NOTES.md.)
/// x0 as in sweep().
template <class L, class T, class Op>
void stream_collide_forced_at(field::Populations<L, T>& pop, const Op& op,
                              const field::VectorField<L::d, double>& force, const ForcedRegion& region,
                              int x0 = 0) {
  constexpr int Q = L::q, D = L::d;
  const auto& g = pop.grid();
  const std::array<T*, Q> P = pop.bases();
  std::array<const double*, D> fp{};
  for (int a = 0; a < D; ++a) fp[a] = force.comp[a].data();
  const int nx = g.n()[0];
  // The region's stretches [begin, end) in memory order: its spans, or its nodes one by one.
  const bool spans = !region.spans.empty();
  const std::ptrdiff_t count = spans ? static_cast<std::ptrdiff_t>(region.spans.size())
                                     : static_cast<std::ptrdiff_t>(region.nodes.size());
  auto begin_of = [&](std::ptrdiff_t k) { return spans ? region.spans[k].begin : region.nodes[k]; };
  auto end_of = [&](std::ptrdiff_t k) { return spans ? region.spans[k].end : region.nodes[k] + 1; };
  const bool velocity = region.wants_velocity();

  parallel_rows<D>(g, [&](std::ptrdiff_t base, const Index<D>&) {
    T* P_l[Q];  // loop invariants in locals, as in sweep()
    for (int i = 0; i < Q; ++i) P_l[i] = P[i];
    const Op op_l = op;
    const double* fp_l[D];
    double* up_l[D];
    for (int a = 0; a < D; ++a) fp_l[a] = fp[a], up_l[a] = region.velocity[a];
    const std::ptrdiff_t row_end = base + nx;
    std::ptrdiff_t lo = 0, hi = count;  // the first stretch at or after the row's start
    while (lo < hi) {
      const std::ptrdiff_t mid = (lo + hi) / 2;
      if (begin_of(mid) < base)
        lo = mid + 1;
      else
        hi = mid;
    }
    std::ptrdiff_t at = base + x0;
    for (std::ptrdiff_t k = lo; k < count && begin_of(k) < row_end; ++k) {
      const std::ptrdiff_t b = begin_of(k), e = end_of(k);
      update_stretch<false, L, T>(P_l, op_l, fp_l, at, static_cast<int>(b - at));
      if (velocity)
        update_stretch<true, L, T, true>(P_l, op_l, fp_l, b, static_cast<int>(e - b), up_l);
      else
        update_stretch<true, L, T>(P_l, op_l, fp_l, b, static_cast<int>(e - b));
      at = e;
    }
    update_stretch<false, L, T>(P_l, op_l, fp_l, at, static_cast<int>(row_end - at));
  });
  pop.flip_parity();
}

/// u + F/(2ρ) into region.velocity at the nodes of `region` (same linear indices; the nodes
/// between them that its spans visit too), from the populations before the sweep: what
/// stream_collide_forced_at writes there, for a block that takes the forced kernel everywhere
/// (a uniform body force) and so never runs it.
template <class L, class T>
void forced_velocity_at(const field::Populations<L, T>& pop, const field::VectorField<L::d, double>& force,
                        const ForcedRegion& region) {
  constexpr int Q = L::q, D = L::d;
  const auto bases = pop.bases();
  const T* P[Q];
  for (int i = 0; i < Q; ++i) P[i] = bases[i];
  const double* fp[D];
  double* up[D];
  for (int a = 0; a < D; ++a) fp[a] = force.comp[a].data(), up[a] = region.velocity[a];
  auto body = [=](std::ptrdiff_t n) __attribute__((always_inline)) {
    T f[Q];
#pragma GCC unroll 19
    for (int i = 0; i < Q; ++i) f[i] = P[i][n];
    store_forced_velocity<L, T>(f, fp, up, n);
  };
  for_each_forced_node<simd_chunk<T>>(region, body);
}

/// Sets every interior node to the equilibrium of (ρ, u(x)) given by init(Index) -> (ρ, Vec).
template <class L, class T, class Init>
void initialise_equilibrium(field::Populations<L, T>& pop, Init&& init) {
  const auto& g = pop.grid();
  field::for_each_interior<L::d>(g, [&](const Index<L::d>& ijk) {
    const auto [rho, u] = init(ijk);
    std::array<T, L::d> uu;
    for (int a = 0; a < L::d; ++a) uu[a] = T(u[a]);
    T feq[L::q];
    equilibrium<L, T>(T(rho), uu, feq);
    const auto n = g.index(ijk);
    for (int i = 0; i < L::q; ++i) pop(i, n) = feq[i];
  });
}

/// ρ and u (with half the force) of node n at the current time.
template <class L, class T>
Moments<L, double> node_moments(const field::Populations<L, T>& pop, std::ptrdiff_t n,
                                const field::VectorField<L::d, double>* force = nullptr) {
  double f[L::q];
  for (int i = 0; i < L::q; ++i) f[i] = pop(i, n);
  double F[L::d] = {};
  if (force)
    for (int a = 0; a < L::d; ++a) F[a] = force->comp[a][n];
  return moments<L, double>(f, force ? F : nullptr);
}

}  // namespace caplab::collision
