# The two set-up commands of the README: `make demo` and `make test`.
BUILD ?= build
JOBS ?= $(shell nproc)
DEMO_OUT ?= out

.PHONY: all deps configure build test demo bench bench-speed clean asan fuzz

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

configure: deps $(BUILD)/CMakeCache.txt

build: configure
	cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

demo: build
	@bash scripts/demo.sh $(BUILD) $(DEMO_OUT)

# The headline tables of docs/BENCHMARKS.md, markdown into BENCH_OUT: `bench` the
# rows of "Latent solvers and transformer in-betweeners" (1 thread), and
# `bench-speed` the table of "Speed" (BENCH_THREADS threads; run it on
# a quiet machine).
BENCH_OUT ?= out/bench
BENCH_MODEL ?= models/motionfield-prior.mfm
BENCH_THREADS ?= 1
bench: build
	@mkdir -p $(BENCH_OUT)
	$(BUILD)/bench/solver-bench --model $(BENCH_MODEL) --threads 1 --max-windows 100 --split validation \
	  --methods interp,detail,nemf-detail --tasks gap,sparse --lengths 15,30,45 --spacings 15,30 --out $(BENCH_OUT)/validation.md
	$(BUILD)/bench/solver-bench --model $(BENCH_MODEL) --threads 1 --max-windows 100 --split validation-mirror \
	  --methods interp,detail,nemf-detail --tasks gap,sparse --lengths 15,30,45 --spacings 15,30 --out $(BENCH_OUT)/validation-mirror.md
	$(BUILD)/bench/motionfield-bench --model $(BENCH_MODEL) --methods interp,nemf-detail --tasks gap --gaps 15,30 \
	  --threads 1 --max-windows 100 --rig mixamo --out $(BENCH_OUT)/mixamo.md

bench-speed: build
	@mkdir -p $(BENCH_OUT)
	$(BUILD)/bench/solver-bench --model $(BENCH_MODEL) --threads $(BENCH_THREADS) --tasks none --speed 10 \
	  --methods nemf-detail --out $(BENCH_OUT)/speed-sparse.md
	$(BUILD)/bench/solver-bench --model $(BENCH_MODEL) --threads $(BENCH_THREADS) --split validation --tasks gap \
	  --lengths 30 --max-windows 20 --methods nemf-detail --out $(BENCH_OUT)/speed-gap.md

# AddressSanitizer + UBSan build in build-asan and the test suite under it
# (docs/RELIABILITY.md, "Sanitizers"); CTest arguments in ASAN_CTEST_ARGS.
asan: deps
	@JOBS=$(JOBS) bash scripts/asan.sh $(ASAN_CTEST_ARGS)

# The libFuzzer targets (clang) in build-fuzz, each run FUZZ_SECONDS seconds
# (docs/RELIABILITY.md, "Fuzzing").
FUZZ_SECONDS ?= 60
fuzz: deps
	@bash scripts/fuzz.sh $(FUZZ_SECONDS)

clean:
	rm -rf $(BUILD)
