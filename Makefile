# What the README's two set-up commands (scripts/setup.sh demo|check, which also install
# thzmap under /usr/local first) run, and a few conveniences.
#   make demo   installs what is missing, builds, and runs the paper's test scene
#   make check  installs what is missing, builds, and runs all tests (also under ASan+UBSan,
#               and a clang build's outputs against the gcc build's),
#               then fuzzes each reader for 20 s (fuzz-ci)
#   make fuzz   fuzzes each reader for FUZZ_SECONDS (default 60) s (tests/fuzz/README.md)
JOBS ?= $(shell nproc)
BUILD ?= build
ASAN_BUILD ?= build-asan
DEMO_OUT ?= out/teraeye
PREFIX ?= /usr/local
FUZZ_BUILD ?= build-fuzz
CLANG_BUILD ?= build-clang
FUZZ_SECONDS ?= 60
FUZZ_CI_SECONDS ?= 20

.PHONY: all deps deps-build build install uninstall demo check test test-asan test-compilers fuzz-build fuzz fuzz-ci bench format clean

all: build

# What building and running need (deps-build), and that with what the tests need (deps):
# scripts/install-deps.sh says which packages are which.
deps-build:
	@bash scripts/install-deps.sh build

deps:
	@bash scripts/install-deps.sh all

build: deps-build
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
	cmake --build $(BUILD) -j $(JOBS)

# The CLI, library, headers, pkg-config file, man page, data and Python package under
# PREFIX; the set-up commands run it (as root) before the demo or the tests.
install: build
	cmake --install $(BUILD) --prefix $(PREFIX) >/dev/null
	@echo "installed thzmap under $(DESTDIR)$(PREFIX)"

# Removes what `make install` put under PREFIX (scripts/uninstall.sh: the list from this
# build, the directories of thzmap's own when empty).
uninstall:
	bash scripts/uninstall.sh $(BUILD) $(PREFIX)

demo: build
	bash scripts/demo.sh $(BUILD)/thzmap $(DEMO_OUT)

test: deps build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

test-asan: deps
	cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Debug -DTHZ_SANITIZE=ON >/dev/null
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  THZ_TEST_SCALE=0.25 ctest --output-on-failure -j $(JOBS) --label-exclude 'slow|no-sanitizer'

# The libFuzzer harnesses (tests/fuzz/): a clang build of their own with ASan+UBSan.
fuzz-build: deps
	cmake -S . -B $(FUZZ_BUILD) -G Ninja -DCMAKE_C_COMPILER=clang \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTHZ_FUZZ=ON >/dev/null
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_harnesses

fuzz: fuzz-build
	bash tests/fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

fuzz-ci: fuzz-build
	bash tests/fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_CI_SECONDS)

# The same outputs from a clang build for any x86-64 as from the gcc build for this
# processor (-march=native): tests/builds/compare.sh. Everything is built with clang
# (tests, bench, the web page's server), so that its -Werror covers all the C, not only
# the program. That build, for any x86-64, also runs under valgrind's memcheck
# (tests/builds/memcheck.sh: memory read before it is written, and what ASan does not
# instrument).
test-compilers: deps build
	cmake -S . -B $(CLANG_BUILD) -G Ninja -DCMAKE_C_COMPILER=clang \
	  -DCMAKE_BUILD_TYPE=Release -DTHZ_NATIVE=OFF >/dev/null
	cmake --build $(CLANG_BUILD) -j $(JOBS)
	bash tests/builds/compare.sh $(BUILD)/thzmap $(CLANG_BUILD)/thzmap $(CURDIR)
	bash tests/builds/memcheck.sh $(CLANG_BUILD)/thzmap $(CURDIR)

check: test test-asan test-compilers fuzz-ci

format:
	clang-format -i $$(git ls-files '*.c' '*.h')

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) $(CLANG_BUILD)

# The benchmark (issue 6): the paper's case in full, scaling, rendering; see README.
bench: build
	$(BUILD)/thzbench --json $(BUILD)/thzbench.json
