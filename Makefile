# The two user commands (see README): `make demo` and `make test`. Both install missing Debian
# packages first (scripts/install-deps.sh, needs root or sudo), then build in build/.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all build deps demo test bench clean

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD_DIR)/CMakeCache.txt:
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS)

demo: deps
	@$(MAKE) --no-print-directory build
	./$(BUILD_DIR)/icef demo

test: deps
	@$(MAKE) --no-print-directory build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) --timeout 900

bench: deps
	@$(MAKE) --no-print-directory build
	@mkdir -p $(BUILD_DIR)/bench
	./$(BUILD_DIR)/bench/icef_bench --benchmark_out=$(BUILD_DIR)/bench/results.json --benchmark_out_format=json

clean:
	rm -rf $(BUILD_DIR)
