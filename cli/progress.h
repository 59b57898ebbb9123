// The progress line of the motionfield CLI on stderr: a bar of the solver's
// iterations (and windows, when the library reports them) with the elapsed
// time and an estimate of the time left, for one job or for each job of a
// batch. Drawn only when stderr is a terminal and --quiet is not given.
#pragma once

#include <chrono>
#include <string>

#include "motionfield.hpp"

namespace motionfield::cli {

class ProgressLine {
 public:
  /// `enabled`: stderr is a terminal and no --quiet.
  explicit ProgressLine(bool enabled);
  ~ProgressLine();

  /// Whether the line is drawn at all.
  bool enabled() const { return enabled_; }

  /// Starts a job: `label` leads the line ("[2/5] line 3" in a batch, the
  /// input file for one job); the clock of the estimate restarts.
  void start(const std::string& label);

  /// One progress report of the running task (mf_progress); redraws at most
  /// ten times a second. Always returns true (never cancels).
  bool update(const mf_progress& p);

  /// Draws `text` as the whole line (no bar, no clock), e.g. how many jobs of
  /// a parallel batch are done.
  void show(const std::string& text);

  /// Clears the line (before a message, and at the end).
  void clear();

  /// True when stderr is a terminal.
  static bool stderr_is_terminal();

 private:
  void draw(const mf_progress& p);

  bool enabled_;
  bool drawn_ = false;
  std::string label_;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace motionfield::cli
