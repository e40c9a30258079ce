# The two user commands (see README): `make demo` and `make test`. Both install missing Debian
# packages first (scripts/install-deps.sh, needs root or sudo), then build in build/.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all build tool deps demo test test-long bench clean sanitize fuzz fuzz-deps format

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD_DIR)/CMakeCache.txt:
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS)

# The command-line tool alone (no tests, benchmarks or fuzzers): what `make demo` needs.
tool: $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS) --target icef

demo: deps
	@$(MAKE) --no-print-directory tool
	./$(BUILD_DIR)/icef demo

test: deps
	@$(MAKE) --no-print-directory build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) --timeout 900 -LE long

# The long tests (ctest label "long": integration.face_detail_test, a full 1000-step training
# checked for fine detail), left out of `make test` to keep CI's suite short.
test-long: deps
	@$(MAKE) --no-print-directory build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -L long

# The benchmarks, then the same kernels (hash grid, MLPs) in PyTorch on the same cores and the ratios
# (build/bench/results.json, build/bench/torch_reference.json).
# Without PyTorch (it could not be installed) the comparison is skipped with a message.
# clang-format (.clang-format: Google style, 110 columns) over every tracked C++ file; `make test`
# checks it (ctest lint.format, scripts/check_format.sh).
format:
	git ls-files '*.h' '*.cc' | xargs clang-format -i

bench: deps
	@$(MAKE) --no-print-directory build
	@mkdir -p $(BUILD_DIR)/bench
	./$(BUILD_DIR)/bench/icef_bench --benchmark_out=$(BUILD_DIR)/bench/results.json --benchmark_out_format=json
	@bash scripts/install-deps.sh --bench || echo "make bench: python3-torch could not be installed"
	@if /usr/bin/python3 -c "import torch" 2>/dev/null; then \
		/usr/bin/python3 scripts/torch_reference_bench.py --cpp-results $(BUILD_DIR)/bench/results.json \
			--json $(BUILD_DIR)/bench/torch_reference.json; \
	else echo "make bench: no PyTorch, so no PyTorch comparison (scripts/install-deps.sh --bench)"; fi

# Sanitizer run (AddressSanitizer + UndefinedBehaviorSanitizer, CMakePresets "asan"): builds only
# the unit-test binaries of the modules that read files and do the rendering arithmetic (a full
# sanitizer build takes far longer on 2 cores) and runs their tests; any sanitizer report fails.
SANITIZE_BUILD_DIR ?= build-asan
SANITIZE_TARGETS ?= icef_core_test icef_math_test icef_io_test icef_data_test icef_render_test
SANITIZE_ENV = ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1 \
	UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1

sanitize: deps
	cmake --preset asan -B $(SANITIZE_BUILD_DIR) -DICEF_BUILD_BENCH=OFF >/dev/null
	cmake --build $(SANITIZE_BUILD_DIR) -j $(JOBS) --target $(SANITIZE_TARGETS)
	cd $(SANITIZE_BUILD_DIR) && $(SANITIZE_ENV) ctest --output-on-failure -j $(JOBS) --timeout 600 \
		-E '_NOT_BUILT|^integration\.|^lint\.'

# libFuzzer targets (fuzz/): each runs FUZZ_SECONDS on its committed seed corpus fuzz/corpus/NAME;
# new inputs go to $(FUZZ_BUILD_DIR)/fuzz/corpus/NAME, crashes to $(FUZZ_BUILD_DIR)/fuzz/crash-NAME-*.
FUZZ_BUILD_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?= dataset checkpoint image

# clang and its libFuzzer runtime are large, so only `make fuzz` installs them.
fuzz-deps: deps
	@if ! command -v clang++ >/dev/null || ! dpkg-query -W -f='$${Status}' libclang-rt-14-dev 2>/dev/null | grep -q "ok installed"; then \
	  echo "fuzz: installing clang libclang-rt-14-dev"; \
	  SUDO=""; [ "$$(id -u)" -ne 0 ] && SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev; \
	fi

fuzz: fuzz-deps
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		-DICEF_FUZZ=ON -DICEF_BUILD_TESTS=OFF -DICEF_BUILD_BENCH=OFF >/dev/null
	cmake --build $(FUZZ_BUILD_DIR) -j $(JOBS) --target $(addprefix icef_fuzz_,$(FUZZ_TARGETS))
	@for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(FUZZ_BUILD_DIR)/fuzz/corpus/$$t; \
	  echo "fuzz: $$t for $(FUZZ_SECONDS) s"; \
	  dict=""; [ -f fuzz/$$t.dict ] && dict="-dict=fuzz/$$t.dict"; \
	  ./$(FUZZ_BUILD_DIR)/fuzz/icef_fuzz_$$t -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 $$dict \
	    -artifact_prefix=$(FUZZ_BUILD_DIR)/fuzz/crash-$$t- $(FUZZ_BUILD_DIR)/fuzz/corpus/$$t fuzz/corpus/$$t \
	    > $(FUZZ_BUILD_DIR)/fuzz/$$t.log 2>&1; rc=$$?; \
	  grep -E '^#[0-9]+[[:space:]]+(INITED|DONE)|stat::|ERROR|SUMMARY' $(FUZZ_BUILD_DIR)/fuzz/$$t.log; \
	  [ $$rc -eq 0 ] || { echo "fuzz: $$t FAILED (exit $$rc), see $(FUZZ_BUILD_DIR)/fuzz/$$t.log"; exit 1; }; \
	done

clean:
	rm -rf $(BUILD_DIR)
