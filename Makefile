# A thin wrapper around CMake (see README.md).
#   make          build (Release) into build/, the program at build/rayes
#   make render   install what is missing, build, render the default scene to out/
#   make test     install what is missing, build, run every test (Release, then
#                 AddressSanitizer + UndefinedBehaviorSanitizer, then the threaded
#                 tests under ThreadSanitizer)
#   make fuzz     build the libFuzzer targets (clang, AddressSanitizer) into
#                 build-fuzz/ and run each fuzz_* for FUZZ_SECONDS (default 60)
#   make bench    build the benchmarks
#   make format   clang-format the lines changed since the last commit
JOBS ?= $(shell nproc)

.PHONY: all build render test test-release test-asan test-tsan test-fuzz fuzz deps deps-test bench format clean

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

test: deps-test test-release test-asan test-tsan test-fuzz

test-release: build
	cd build && ctest --output-on-failure -j $(JOBS)

# new_delete_type_mismatch=0: OpenImageIO 2.4's TextureSystem::destroy
# deletes its implementation through the base class with a sized delete,
# inside the library (rayes' two C++ files delete what they new).
# intercept_tls_get_addr=0: LeakSanitizer's tracer thread dies at exit
# ("Tracer caught signal 11 ... LeakSanitizer has encountered a fatal
# error") after every check of a test has passed, reading a bogus range it
# recorded for a dlopen'ed library's dynamic TLS (its log: "DTLS 8 at
# 0x000000002562-0x005000003664"; glibc 2.36 with GCC 12's sanitizer);
# seen once in about 50 runs of test_texture_aa, then in every run of
# test_lights once the mesh light tests came. Without the interception it
# does not track dynamic TLS, and no test reports a leak.
# --repeat until-pass:2: for any other flake of the tracer; a test that
# fails for a reason of its own fails the second time too.
test-asan:
	@test -f build-asan/Makefile || cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DRAYES_SANITIZE=ON
	cmake --build build-asan -j $(JOBS)
	cd build-asan && ASAN_OPTIONS=detect_leaks=1:new_delete_type_mismatch=0:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure --repeat until-pass:2 -j $(JOBS)

# ThreadSanitizer on the threaded code of our own: the cache (its stress
# test hammers a tiny budget from many threads), the renderer's thread
# pool, the shader plugin registry (threads loading plugins at once; the
# plugins are built with TSan too) and the texture cache (threads loading,
# evicting and reloading MIP levels on a tiny budget), and the grid hider
# (threads shading grids on first sight behind striped locks), and whole
# renders on 1 to 4 threads (the determinism tests), the progressive
# session (passes cancelled from another thread), opacity and volume renders
# (threads filling the opacity cache's grid and brick entries from inside
# Embree's occlusion filter), point-based GI (threads shading the point
# cloud's grids and gathering from it) and rayes view (its driver
# and window threads, headless and under SDL's dummy driver and Xvfb; Mesa's
# software GL driver is suppressed too). Embree and
# TBB are not instrumented: tools/tsan.supp suppresses reports inside them.
# A test file that marks some cases TEST_THREADS (tests/test.h) runs only
# those here: the images and numbers of the rest are checked by the Release
# and AddressSanitizer builds at a twentieth of the cost.
TSAN_TESTS = cache_test_cache cache_test_cache_stress util_test_math util_test_half util_test_sky \
             shade_test_plugin shade_test_texture_threads render_test_hider \
             render_test_determinism render_test_adaptive render_test_session render_test_opacity render_test_volume \
             render_test_subsurface render_test_instances render_test_motion render_test_dof render_test_pbgi \
             render_test_envguide render_test_aov \
             rayes_app app_test_view app_test_checkpoint
test-tsan:
	@# configured every time: the targets below must be known to make even if added since
	@cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRAYES_TSAN=ON >/dev/null
	cmake --build build-tsan -j $(JOBS) --target $(TSAN_TESTS)
	cd build-tsan && TSAN_OPTIONS="halt_on_error=1 suppressions=$(CURDIR)/tools/tsan.supp" ctest --output-on-failure -j $(JOBS) -R '^(cache|util)/|^shade/test_plugin$$|^shade/test_texture_threads$$|^render/test_(hider|determinism|adaptive|session|opacity|volume|subsurface|instances|motion|dof|pbgi|envguide|aov)$$|^app/test_(view|checkpoint)$$'

# Fuzzing: every tests/fuzz/fuzz_NAME.c is a target, run on a scratch copy
# of its seeds tests/fuzz/corpus_NAME/ (the repository's seeds stay as they
# are) for FUZZ_SECONDS. A crash stops make; libFuzzer writes the input to
# build-fuzz/artifacts/. The targets' own stderr (reader warnings) is closed.
# Warnings are not errors there: clang warns on some code gcc accepts.
FUZZ_SECONDS ?= 60
FUZZ_TARGETS = $(patsubst tests/fuzz/%.c,%,$(wildcard tests/fuzz/fuzz_*.c))
fuzz:
	@# configured every time: a target added since the last run must be known to make
	@CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRAYES_FUZZ=ON -DRAYES_SANITIZE=ON -DRAYES_WERROR=OFF >/dev/null
	cmake --build build-fuzz -j $(JOBS) --target $(FUZZ_TARGETS)
	@mkdir -p build-fuzz/artifacts
	@set -e; for t in $(FUZZ_TARGETS); do \
	  name=$${t#fuzz_}; corpus=build-fuzz/corpus/$$name; \
	  rm -rf $$corpus; mkdir -p $$corpus; \
	  if [ -d tests/fuzz/corpus_$$name ]; then cp tests/fuzz/corpus_$$name/* $$corpus/; fi; \
	  echo "fuzz: $$t for $(FUZZ_SECONDS) s on a copy of tests/fuzz/corpus_$$name"; \
	  if ! build-fuzz/tests/fuzz/$$t -max_total_time=$(FUZZ_SECONDS) -timeout=20 \
	      -rss_limit_mb=2048 -close_fd_mask=2 -print_final_stats=1 \
	      -artifact_prefix=build-fuzz/artifacts/$$t- $$corpus > build-fuzz/$$t.log 2>&1; then \
	    cat build-fuzz/$$t.log; echo "fuzz: $$t FAILED (log build-fuzz/$$t.log)"; exit 1; \
	  fi; \
	  grep -E '^stat::(number_of_executed_units|peak_rss_mb)|^#[0-9]+.*DONE' build-fuzz/$$t.log; \
	done

# make test fuzzes each target briefly.
test-fuzz:
	$(MAKE) fuzz FUZZ_SECONDS=20

bench: build

# Only the lines changed since the last commit (git clang-format), with the
# project's .clang-format: the sources' hand-aligned tables and comments stay.
format:
	git clang-format -f

clean:
	rm -rf build build-asan build-tsan build-fuzz out
