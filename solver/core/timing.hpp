// Wall-clock accounting of run stages (fluid, coupling, IB, diagnostics, output).
#pragma once

#include <chrono>

namespace caplab::core {

/// Runs f() and adds its wall time in seconds to `acc`.
template <class F>
void timed(double& acc, F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  acc += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace caplab::core
