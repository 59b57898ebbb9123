// Small helpers shared by the benchmark programs: number formatting for the
// markdown tables and wall-clock timing (their options: bench/options.h).
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace mf::bench {

/// `v` with `decimals` digits after the point ("%.*f").
std::string fixed(double v, int decimals);

/// Milliseconds of wall time since `t0`.
double ms_since(std::chrono::steady_clock::time_point t0);

/// Prints `head` (the markdown up to the table's header rows), then the rows
/// `rows(T)` of every gap T as each is measured, on standard output; the whole
/// text also goes to the file `out` unless it is empty.
void stream_gap_table(const std::string& head, const std::vector<int>& gaps,
                      const std::function<std::string(int)>& rows, const std::string& out);

}  // namespace mf::bench
