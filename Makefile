# Sprig's two commands. Each installs what is missing, configures, builds, then runs.
#   make test     build and run the whole test suite (ctest)
#   make gallery  render every shipped species into gallery/out/
BUILD   ?= build
JOBS    ?= $(shell nproc)
SPRIG   := $(BUILD)/sprig
QUALITY ?= draft

.PHONY: all deps configure build test gallery bench clean

all: build

deps:
	@bash scripts/install-deps.sh
	@bash scripts/extract-meshes.sh species/meshes

configure: deps
	@cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

gallery: build
	@$(SPRIG) gallery -o gallery/out --quality $(QUALITY)

bench: build
	@for b in $(BUILD)/bench/*; do echo "== $$b"; $$b || exit 1; done

clean:
	@rm -rf $(BUILD)
