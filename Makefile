# A thin wrapper around CMake (see README.md).
#   make          build (Release) into build/, the program at build/rayes
#   make render   install what is missing, build, render the default scene to out/
#   make test     install what is missing, build, run every test (Release, then
#                 AddressSanitizer + UndefinedBehaviorSanitizer, then the threaded
#                 tests under ThreadSanitizer)
#   make bench    build the benchmarks
#   make format   clang-format the sources
JOBS ?= $(shell nproc)

.PHONY: all build render test test-release test-asan test-tsan deps deps-test bench format clean

all: build

build:
	@test -f build/Makefile || cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
	cmake --build build -j $(JOBS)

deps:
	tools/install-deps

deps-test:
	tools/install-deps --test

render: deps build
	mkdir -p out
	build/rayes render cornell -o out/default.exr -o out/default.png

test: deps-test test-release test-asan test-tsan

test-release: build
	cd build && ctest --output-on-failure -j $(JOBS)

test-asan:
	@test -f build-asan/Makefile || cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DRAYES_SANITIZE=ON
	cmake --build build-asan -j $(JOBS)
	cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j $(JOBS)

# ThreadSanitizer on the threaded code of our own: the cache (its stress
# test hammers a tiny budget from many threads), the renderer's thread
# pool, the shader plugin registry (threads loading plugins at once; the
# plugins are built with TSan too) and the texture cache (threads loading,
# evicting and reloading MIP levels on a tiny budget), and the grid hider
# (threads shading grids on first sight behind striped locks), and whole
# renders on 1 to 4 threads (the determinism tests). Embree and
# TBB are not instrumented: tools/tsan.supp suppresses reports inside them.
TSAN_TESTS = cache_test_cache cache_test_cache_stress util_test_math util_test_half \
             shade_test_plugin shade_test_texture_threads render_test_hider \
             render_test_determinism
test-tsan:
	@test -f build-tsan/Makefile || cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRAYES_TSAN=ON
	cmake --build build-tsan -j $(JOBS) --target $(TSAN_TESTS)
	cd build-tsan && TSAN_OPTIONS="halt_on_error=1 suppressions=$(CURDIR)/tools/tsan.supp" ctest --output-on-failure -R '^(cache|util)/|^shade/test_plugin$$|^shade/test_texture_threads$$|^render/test_(hider|determinism)$$'

bench: build

format:
	clang-format -i $$(git ls-files '*.c' '*.h')

clean:
	rm -rf build build-asan build-tsan out
