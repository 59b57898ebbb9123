// Small helpers shared by the benchmark programs: number formatting for the
// markdown tables, comma-separated flag values and wall-clock timing.
#pragma once

#include <chrono>
#include <string>
#include <vector>

namespace mf::bench {

/// `v` with `decimals` digits after the point ("%.*f").
std::string fixed(double v, int decimals);

/// "a,b,c" -> {"a", "b", "c"}; empty items are dropped. Throws InputError on
/// a list with no item.
std::vector<std::string> split_list(const std::string& s);

/// "5,15,30" -> {5, 15, 30}. Throws InputError on an empty list or an item
/// that is not an integer.
std::vector<int> int_list(const std::string& s);

/// Milliseconds of wall time since `t0`.
double ms_since(std::chrono::steady_clock::time_point t0);

}  // namespace mf::bench
