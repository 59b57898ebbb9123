#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>

#include "cli.h"

namespace motionfield::cli {
namespace {

using Clock = std::chrono::steady_clock;

// "1m05s", "42s".
std::string duration_text(double seconds) {
  char buf[32];
  const long s = std::lround(std::max(0.0, seconds));
  if (s >= 60)
    std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%lds", s);
  return buf;
}

}  // namespace

ProgressLine::ProgressLine(bool enabled) : enabled_(enabled) {}

ProgressLine::~ProgressLine() { clear(); }

bool ProgressLine::stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

void ProgressLine::start(const std::string& label) {
  label_ = printable(label);
  start_ = Clock::now();
  last_draw_ = Clock::time_point();
  if (!enabled_) return;
  mf_progress none{};
  none.struct_size = sizeof none;
  draw(none);
}

bool ProgressLine::update(const mf_progress& p) {
  if (!enabled_) return true;
  const Clock::time_point now = Clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100) && p.iteration < p.max_iterations) return true;
  draw(p);
  return true;
}

void ProgressLine::draw(const mf_progress& p) {
  last_draw_ = Clock::now();
  const double elapsed = std::chrono::duration<double>(last_draw_ - start_).count();
  std::string line = label_;
  if (p.max_iterations > 0) {
    const int width = 24;
    const double done = std::min(1.0, std::max(0.0, static_cast<double>(p.iteration) / p.max_iterations));
    const int filled = static_cast<int>(done * width);
    line += " [" + std::string(static_cast<size_t>(filled), '=') + std::string(static_cast<size_t>(width - filled), ' ') +
            "] " + std::to_string(p.iteration) + "/" + std::to_string(p.max_iterations) + " iterations";
    if (p.struct_size >= offsetof(mf_progress, window_count) + sizeof(int32_t) && p.window_count > 1)
      line += ", window " + std::to_string(p.window + 1) + "/" + std::to_string(p.window_count);
    line += ", " + duration_text(elapsed);
    // The cap is an upper bound: solvers often stop earlier, so the estimate is too.
    if (p.iteration > 0 && done < 1.0) line += ", at most " + duration_text(elapsed / done - elapsed) + " left";
  } else {
    line += " " + duration_text(elapsed);
  }
  std::fprintf(stderr, "\r\033[K%s", line.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::show(const std::string& text) {
  if (!enabled_) return;
  std::fprintf(stderr, "\r\033[K%s", printable(text).c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::clear() {
  if (!drawn_) return;
  std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace motionfield::cli
