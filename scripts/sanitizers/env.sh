# The sanitizer run-time options of `make asan` and scripts/fuzz.sh (sourced).
# Each choice is explained in docs/RELIABILITY.md ("Sanitizers").
_mf_sanitizers_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$_mf_sanitizers_dir/lsan.supp:print_suppressions=0}
