// Small helpers shared by the benchmark programs: number formatting for the
// markdown tables and wall-clock timing (their options: bench/options.h).
#pragma once

#include <chrono>
#include <string>

namespace mf::bench {

/// `v` with `decimals` digits after the point ("%.*f").
std::string fixed(double v, int decimals);

/// Milliseconds of wall time since `t0`.
double ms_since(std::chrono::steady_clock::time_point t0);

}  // namespace mf::bench
