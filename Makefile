# The two set-up commands of the README: `make demo` and `make test`.
BUILD ?= build
JOBS ?= $(shell nproc)
DEMO_OUT ?= out

.PHONY: all deps configure build test demo bench clean asan fuzz

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
