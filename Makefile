# Sprig's two commands. Each installs what is missing, configures, builds, then runs.
#   make test     build and run the whole test suite (ctest)
#   make gallery  render every shipped species into gallery/out/
#   make sanitize build with clang, AddressSanitizer and UBSan in build-asan/, run ctest there
#                 (all but the tests labelled heavy and tagged [slow]: docs/ROBUSTNESS.md, "CI")
#   make fuzz     build the libFuzzer targets (build-asan/fuzz/) and run each FUZZ_SECONDS
BUILD   ?= build
JOBS    ?= $(shell nproc)
SPRIG   := $(BUILD)/sprig
QUALITY ?= draft
# `make gallery` runs this many shards side by side, one thread each, then merges them
# (docs/GALLERY.md "make gallery"): one process's serial parts (solid meshing, GIF
# writing, reading) overlap the other's work. The result is the same bytes as one process.
GALLERY_SHARDS ?= $(JOBS)
ASAN_BUILD   ?= build-asan
FUZZ_SECONDS ?= 60
CCACHE := $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# ccache hashes paths relative to the checkout and not the build folder, so every clone
# (CI's, a worktree, the fresh-machine test's) shares one cache.
export CCACHE_BASEDIR   ?= $(CURDIR)
export CCACHE_NOHASHDIR ?= 1
# -O1 -g1: sanitizer reports with line numbers, at about half the compile time of -O2 -g.
ASAN_CONFIG := CC=clang-14 CXX=clang++-14 cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1" -DSPRIG_SANITIZE=ON -DSPRIG_FUZZ=ON $(CCACHE)
# intercept_tls_get_addr=0: LeakSanitizer's bookkeeping of dynamic TLS (the libraries sprig
# dlopens, backends/) records a garbage range under Debian 12's glibc and its tracer crashes
# at exit ("Tracer caught signal 11"); leaks are still checked, static TLS still scanned.
export ASAN_OPTIONS  ?= detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=0:intercept_tls_get_addr=0
export UBSAN_OPTIONS ?= print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS  ?= suppressions=$(CURDIR)/fuzz/lsan.supp:print_suppressions=0

.PHONY: all deps configure build test gallery bench clean sanitize fuzz

all: build

deps:
	@bash scripts/install-deps.sh
	@bash scripts/extract-meshes.sh species/meshes

configure: deps
	@cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CCACHE) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

gallery: build
	@pids=; for i in $$(seq 0 $$(($(GALLERY_SHARDS) - 1))); do \
	  $(SPRIG) --threads 1 gallery -o gallery/out --quality $(QUALITY) --shard $$i/$(GALLERY_SHARDS) & pids="$$pids $$!"; \
	done; status=0; for p in $$pids; do wait $$p || status=1; done; exit $$status
	@$(SPRIG) gallery --merge gallery/out

bench: build
	@for b in $(BUILD)/bench/*; do echo "== $$b"; $$b || exit 1; done
	@echo "== bench/startup.sh"; bash bench/startup.sh $(SPRIG)

sanitize: deps
	@$(ASAN_CONFIG) >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS)
	@cd $(ASAN_BUILD) && ctest --output-on-failure -j $(JOBS) -LE heavy

fuzz: deps
	@$(ASAN_CONFIG) >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS) --target $(addprefix fuzz_,grammar view background function enviro expression derive species_tree species_shell species_blob species_organism species_solid polymesh image volume)
	@bash fuzz/run.sh $(ASAN_BUILD) $(FUZZ_SECONDS)

clean:
	@rm -rf $(BUILD) $(ASAN_BUILD)
