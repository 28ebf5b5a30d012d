// Memory bandwidth of this machine, measured by STREAM-like kernels (McCalpin 1995).
//
// Copy c = a and triad a = b + s·c on three arrays of doubles much larger than the last-level
// cache, and the in-place update b = s·b (read and write back one array, as the in-place
// lattice Boltzmann kernel does), parallelised with OpenMP (static schedule, parallel first
// touch with the same schedule), ordinary loads and stores. Bytes are counted the STREAM way:
// copy 2 × 8 B, triad 3 × 8 B and update 2 × 8 B per element; the write-allocate read of the
// stored line is not counted (the hardware moves 3 × 8 B and 4 × 8 B for copy and triad; the
// update's stores hit lines it has just read, so it moves what it counts). The result is the
// best repetition, the first one excluded as warm-up.
#pragma once

#include <cstddef>

namespace caplab::bench {

/// Bandwidth of one thread count, in GB/s (10⁹ B/s), STREAM byte counting.
struct StreamResult {
  int threads = 0;
  std::size_t array_bytes = 0;  // bytes of each of the three arrays
  int repetitions = 0;          // timed repetitions (after one warm-up)
  double copy_gbs = 0;          // best repetition
  double triad_gbs = 0;         // best repetition
  double update_gbs = 0;        // best repetition
  double copy_gbs_median = 0;
  double triad_gbs_median = 0;
  double update_gbs_median = 0;
  bool validated = false;  // the arrays hold the values the kernels must produce
};

/// Runs copy, triad and update with `threads` OpenMP threads on three arrays of `array_bytes` each.
/// Throws core::Error if the arguments are out of range or the result fails validation.
StreamResult measure_stream_bandwidth(int threads, std::size_t array_bytes, int repetitions);

}  // namespace caplab::bench
