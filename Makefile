# obscura: one entry point.
#
#   make          build/libobscura.a and build/obscura
#   make deps     install the Debian packages the build and tests need
#   make demo     run the bundled example (no daemon)
#   make test     unit + end-to-end tests, then the same under ASan/UBSan
#   make bench    benchmarks (bench/RESULTS.md)
#   make quality  AO against ray-traced ground truth (bench/QUALITY.md)
#   make quality-masks  the object masks against a hidden-object Cycles render (needs blender)
#   make bake-quality  baked vertices against the per-pixel reference (bench/BAKE.md)
#   make fuzz     libFuzzer targets: binary protocol, EXR readers, other input files (clang; tests/fuzz/fuzz.mk)
#   make readme   regenerate README.md's parameter and daemon option tables
#   make samples  regenerate core/chain/sample_tables.c (VAO++ 4.5 sample sets)
#
# BUILD selects the output folder, so the sanitizer build lives beside the
# normal one: make BUILD=build/asan SAN=1.

BUILD ?= build
SAN ?= 0
DEBUG ?= 0

CC ?= cc
PKGS := OpenEXR egl osmesa libpng libcjson
# OpenEXR's C core library (openexr.h) reads and writes; its C++ library
# only writes deep files (core/io/exr_deep_write.cpp, see below).
EXR_CFLAGS := $(shell pkg-config --cflags OpenEXR 2>/dev/null)
PKG_CFLAGS := $(shell pkg-config --cflags egl osmesa libpng libcjson nettle 2>/dev/null) $(EXR_CFLAGS)
# nettle: SHA-256 of the program cache's keys (core/gl/progcache.c).
# EGL and OSMesa: their headers only; the libraries are opened at run time
# when a GL backend is chosen (core/gl/libs.c), so that nothing linked
# needs GL and the CPU device runs on a node without it.
PKG_LIBS := -lOpenEXRCore-3_1 $(shell pkg-config --libs libpng libcjson nettle 2>/dev/null) -lz -lm -lpthread -ldl
# Scene loading (core/ground/scene.c: assimp) and the ray-traced reference
# (core/ground/reference.c: Embree 3, no .pc file) and the bake's least-squares
# solve (core/bake/fit.c: SuiteSparse CHOLMOD) and its LODs (core/bake/simplify.c:
# meshoptimizer, a C API over a C++ library) live in libobscura.a too; as
# static members they are linked only into binaries that call them, and
# --as-needed keeps the shared libraries out of the others (the daemon).
PKG_LIBS += -Wl,--push-state,--as-needed $(shell pkg-config --libs assimp 2>/dev/null) -lembree3 -lcholmod -lmeshoptimizer -Wl,--pop-state
# The deep EXR writer (core/io/exr_deep_write.cpp, OpenEXR's C++ deep API; the
# C API of 3.1 cannot write deep data): the same arrangement, so only the
# binaries that write deep files (the CLI, tests) need the C++ libraries.
PKG_LIBS += -Wl,--push-state,--as-needed $(shell pkg-config --libs OpenEXR 2>/dev/null) -lstdc++ -Wl,--pop-state
CXX ?= c++
CXXFLAGS ?= -O2 -g
CXXFLAGS += -std=c++14 -Wall -Wextra -Wshadow -fno-strict-aliasing

CFLAGS ?= -O2 -g
CFLAGS += -std=c11 -D_DEFAULT_SOURCE -Wall -Wextra -Wshadow -Wstrict-prototypes \
          -Wno-missing-field-initializers -fno-strict-aliasing
CPPFLAGS += -Iinclude -I$(BUILD)/gen
# core's internal headers are seen by core itself and by the tests, benches
# and developer tools that exercise its insides; daemon/, protocol/ and
# clients/ are built without them, so `obs__` names stay internal.
CORE_INC := -Icore
$(BUILD)/obj/core/%.o: CPPFLAGS += $(CORE_INC)
# The CPU device's kernels run pixels in SIMD lanes through OpenMP's simd
# pragma (gcc -fopenmp-simd: the pragma only, no OpenMP runtime);
# -fno-trapping-math lets gcc compute both sides of a select in the lanes
# and -fno-math-errno sqrtf be one instruction in them (no FP exception
# flag nor errno is read; no value changes).
$(BUILD)/obj/core/chain/%_cpu.o: CFLAGS += -fopenmp-simd -fno-trapping-math -fno-math-errno
ifeq ($(SAN),1)
CFLAGS += -fsanitize=address,undefined,float-cast-overflow -fno-omit-frame-pointer -fno-sanitize-recover=undefined,float-cast-overflow
CXXFLAGS += -fsanitize=address,undefined,float-cast-overflow -fno-omit-frame-pointer -fno-sanitize-recover=undefined,float-cast-overflow
LDFLAGS += -fsanitize=address,undefined,float-cast-overflow
# intercept_tls_get_addr=0: gcc 12's LeakSanitizer reads a dynamic TLS block
# of a library opened with dlopen (Mesa's, core/gl/libs.c) at a bogus address
# and its tracer dies at exit ("Tracer caught signal 11", after "DTLS ... at
# 0x...ce0"); without the interception it scans no dynamic TLS, which can
# only report more leaks, never hide one.
export LSAN_OPTIONS := suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0:intercept_tls_get_addr=0
export UBSAN_OPTIONS := print_stacktrace=1:halt_on_error=1
endif
ifeq ($(DEBUG),1)
CPPFLAGS += -DOBS_DEBUG=1
endif

CORE_SRC := $(wildcard core/*.c core/*/*.c)
CORE_CXX_SRC := $(wildcard core/*.cpp core/*/*.cpp)
CORE_OBJ := $(CORE_SRC:%.c=$(BUILD)/obj/%.o) $(CORE_CXX_SRC:%.cpp=$(BUILD)/obj/%.o)
SHADERS := $(wildcard core/shaders/*.glsl)
SHADER_HDR := $(BUILD)/gen/obs_shaders.h

CLI_SRC := $(wildcard clients/*.c)
CLI_OBJ := $(CLI_SRC:%.c=$(BUILD)/obj/%.o)

UNIT_SRC := $(filter-out tests/unit/nogl/%,$(wildcard tests/unit/*/test_*.c))
UNIT_BIN := $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)
# Tests that must link without the GL libraries (libobscura.a, libm and
# cmocka only): the CPU twin of the chain.
NOGL_SRC := $(wildcard tests/unit/nogl/test_*.c)
NOGL_BIN := $(NOGL_SRC:tests/unit/%.c=$(BUILD)/tests/%)

LIB := $(BUILD)/libobscura.a
CLI := $(BUILD)/obscura
BENCH := $(BUILD)/frame_bench
# VAO++ Table 1: the extensions timed with GL timer queries.
EXT_BENCH := $(BUILD)/extensions_bench
# Developer tool: a G-buffer EXR upscaled to WxH (tests/e2e/load.sh, bench).
UPSCALE := $(BUILD)/exr_upscale
# Developer tool of make quality: EXR channels side by side in one PNG.
QSTRIP := $(BUILD)/quality_strip
DAEMON_BENCH := $(BUILD)/daemon_bench

# The daemon and the wire protocol bring their own rules; they add their
# binaries to `all` and their e2e prerequisites to E2E_DEPS.
-include protocol/protocol.mk daemon/daemon.mk clients/clients.mk tests/fuzz/fuzz.mk
E2E_DEPS += $(UPSCALE)

.PHONY: all deps demo demo-run test test-long fuzz-replay check unit e2e loops headers readme readme-check samples bench quality quality-masks quality-deep quality-heldout bake-quality clean deep-fixture
.DEFAULT_GOAL := all

all: $(LIB) $(CLI) $(EXTRA_BINS)

# ---- dependencies -------------------------------------------------------
deps:
	@tools/deps.sh


# ---- build --------------------------------------------------------------
$(SHADER_HDR): $(SHADERS) core/shaders/shared.h tools/embed_shaders.sh
	@mkdir -p $(dir $@)
	tools/embed_shaders.sh core/shaders/shared.h $(SHADERS) > $@.tmp && mv $@.tmp $@

$(BUILD)/obj/%.o: %.c | $(SHADER_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(PKG_CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/obj/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CPPFLAGS) $(CXXFLAGS) $(EXR_CFLAGS) -MMD -MP -c $< -o $@

$(LIB): $(CORE_OBJ)
	@rm -f $@
	ar rcs $@ $^

# The CLI is also a client of obscurad (clients/remote.c): it links the
# protocol library.
$(BUILD)/obj/clients/%.o: CPPFLAGS += -Iprotocol
$(CLI): $(CLI_OBJ) $(PROTO_LIB) $(LIB)
	$(CC) $(LDFLAGS) -o $@ $(CLI_OBJ) $(PROTO_LIB) $(LIB) $(PKG_LIBS)

$(BENCH): bench/frame_bench.c $(LIB)
	$(CC) $(CPPFLAGS) $(CORE_INC) $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(LIB) $(LDFLAGS) $(PKG_LIBS)

$(EXT_BENCH): bench/extensions_bench.c $(LIB)
	$(CC) $(CPPFLAGS) $(CORE_INC) $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(LIB) $(LDFLAGS) $(PKG_LIBS)

$(UPSCALE): tools/exr_upscale.c $(LIB)
	$(CC) $(CPPFLAGS) $(CORE_INC) $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(LIB) $(LDFLAGS) $(PKG_LIBS)

# Deep input: OITAO Table I structure (bench/RESULTS.md, "Deep input").
DEEP_BENCH := $(BUILD)/deep_bench
# The blur kernel in Google's Highway (libhwy-dev) against the library's
# OpenMP simd form (bench/blur_hwy.cc); built by make bench only, the
# library does not link Highway.
HWY_BENCH := $(BUILD)/blur_hwy_bench
$(HWY_BENCH): bench/blur_hwy.cc $(LIB)
	$(CXX) -I. $(CPPFLAGS) $(CORE_INC) $(CXXFLAGS) -std=c++17 -ffp-contract=off $< -o $@ $(LIB) $(LDFLAGS) $(PKG_LIBS) -lhwy
# The same for ao_definition rays' conversion (bench/rays_hwy.cc).
RAYS_HWY_BENCH := $(BUILD)/rays_hwy_bench
$(RAYS_HWY_BENCH): bench/rays_hwy.cc $(LIB)
	$(CXX) -I. $(CPPFLAGS) $(CORE_INC) $(CXXFLAGS) -std=c++17 -ffp-contract=off $< -o $@ $(LIB) $(LDFLAGS) $(PKG_LIBS) -lhwy
$(DEEP_BENCH): bench/deep_bench.c $(LIB)
	$(CC) $(CPPFLAGS) $(CORE_INC) $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(LIB) $(LDFLAGS) $(PKG_LIBS)

# The deep test fixture, written with OpenEXR's C++ deep API (the C API of
# 3.1 cannot write deep data); its output tests/data/deep_small.exr is
# committed, so only this target needs the C++ library.
deep-fixture:
	@mkdir -p $(BUILD)
	c++ -O1 -std=c++14 $$(pkg-config --cflags OpenEXR) tools/deep_fixture.cpp -o $(BUILD)/deep_fixture $$(pkg-config --libs OpenEXR)
	$(BUILD)/deep_fixture tests/data/deep_small.exr

$(QSTRIP): tools/quality_strip.c $(LIB)
	$(CC) $(CPPFLAGS) $(CORE_INC) $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(LIB) $(LDFLAGS) $(PKG_LIBS)

# The daemon bench is a client: the CLI's remote code and the protocol.
$(DAEMON_BENCH): bench/daemon_bench.c $(BUILD)/obj/clients/remote.o $(PROTO_LIB) $(LIB)
	$(CC) $(CPPFLAGS) $(CORE_INC) -Iclients -Iprotocol $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(BUILD)/obj/clients/remote.o $(PROTO_LIB) $(LIB) $(LDFLAGS) $(PKG_LIBS)

# PROTO_LIB and EXTRA_LIBS come from protocol.mk / daemon.mk when present.
$(BUILD)/tests/%: tests/unit/%.c $(PROTO_LIB) $(LIB) tests/unit/testutil.h $(wildcard tests/unit/core/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CORE_INC) -Itests/unit $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(PROTO_LIB) $(LIB) $(LDFLAGS) $(PKG_LIBS) $(EXTRA_LIBS) -lcmocka

# The bake tests' scene helpers (tests/unit/level/bake_testutil.h), for the
# tests of core/level, core/bake and core/dynamic.
$(filter $(BUILD)/tests/level/% $(BUILD)/tests/bake/% $(BUILD)/tests/dynamic/%,$(UNIT_BIN)): $(wildcard tests/unit/level/*.h)

$(BUILD)/tests/nogl/%: tests/unit/nogl/%.c $(LIB) tests/unit/testutil.h $(wildcard tests/unit/core/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CORE_INC) -Itests/unit $(CFLAGS) $< -o $@ $(LIB) $(LDFLAGS) -lm -lcmocka

-include $(CORE_OBJ:.o=.d) $(CLI_OBJ:.o=.d)


# ---- demo ---------------------------------------------------------------
# The packages may only now have been installed: build in a fresh make, so
# that pkg-config is asked again.
demo: deps
	@$(MAKE) --no-print-directory demo-run

demo-run: all
	@mkdir -p out
	$(CLI) info
	$(CLI) ao tests/data/room_small.exr --camera tests/data/room_small.camera.json \
	    --output both -o out/room_small.exr
	$(CLI) ao tests/data/room_small.exr --camera tests/data/room_small.camera.json \
	    --output ao -o out/room_small_ao.png
	$(CLI) ao tests/data/room_small.exr --camera tests/data/room_small.camera.json \
	    --output composite -o out/room_small_composite.png
	@echo "demo: wrote out/room_small.exr (AO.Y + R,G,B,A), out/room_small_ao.png, out/room_small_composite.png"

# ---- tests --------------------------------------------------------------
# make test = the whole suite, then the same suite under ASan/UBSan but for
# the sanitizer pass of the slowest e2e scripts (each over 20 s under ASan),
# which make test-long runs, and then the e2e suite once more on the CPU
# device (plain build; fuzz.sh left out: it fuzzes decoders, whatever the
# device), and then every fuzz target's seeds replayed with clang, which it
# installs (CI runs both).
E2E_LONG = bake progcache dynamic run load output deploy hostile_binary bakes python_client \
           guards hostile_http provenance remote
test: deps
	$(MAKE) check
	$(MAKE) check BUILD=build/asan SAN=1 E2E_SKIP="$(E2E_LONG)"

test-long: deps
	$(MAKE) all e2e BUILD=build/asan SAN=1 E2E_ONLY="$(E2E_LONG)"
	$(MAKE) all e2e OBSCURA_BACKEND=cpu E2E_SKIP=fuzz
	$(MAKE) fuzz-replay

# Every fuzz target's seeds and regression inputs replayed, no mutation
# (the same inputs on every run), with clang installed first (as root).
fuzz-replay:
	tools/deps.sh --fuzz
	FUZZ_SECONDS=0 BUILD=$(BUILD) tests/e2e/fuzz.sh

check: all headers loops unit e2e readme-check

# The README's parameter table is generated from the parameter table.
readme: $(CLI) $(BUILD)/obscurad
	tools/readme_params.sh $(CLI) $(BUILD)/obscurad README.md

# The sample sets are the generator's output, checked in as C source
# (tests/unit/core/test_samples.c fails when they are stale).
samples: $(CLI)
	$(CLI) samples --c > core/chain/sample_tables.c.tmp && mv core/chain/sample_tables.c.tmp core/chain/sample_tables.c

readme-check: $(CLI) $(BUILD)/obscurad
	@tools/readme_params.sh --check $(CLI) $(BUILD)/obscurad README.md && echo "readme: generated tables up to date"

unit: $(UNIT_BIN) $(NOGL_BIN)
	@for t in $(NOGL_BIN); do \
	  if readelf -d $$t | grep -E 'NEEDED.*lib(EGL|OSMesa|GL|OpenGL)' ; then \
	    echo "unit: $$t needs a GL library"; exit 1; fi; done
	@tests/run_unit.sh $(UNIT_BIN) $(NOGL_BIN)

# No two source files call each other in a loop, in each part of the tree
# (tools/call_loops.py: nm of the objects).
loops: $(CORE_OBJ) $(DAEMON_OBJ) $(PROTO_OBJ) $(CLI_OBJ)
	@tools/call_loops.py $(CORE_OBJ)
	@tools/call_loops.py $(DAEMON_OBJ)
	@tools/call_loops.py $(PROTO_OBJ) $(CLI_OBJ)
	@tools/call_loops.py --internal $(DAEMON_OBJ) $(PROTO_OBJ) $(CLI_OBJ)

# Every tests/e2e/*.sh runs with the binaries' paths in the environment,
# two at a time on two cores (tests/run_e2e.sh); those in E2E_ALONE time
# the daemon and run afterwards, one at a time.  E2E_ONLY / E2E_SKIP: the
# scripts' names (without .sh) to run, or to leave to another target.
# The program cache (and auto's kept choice, devices.txt) in a folder of
# the build's own, not the user's ~/.cache: a choice kept there by a run
# of `--backend auto` would move every GL check onto the CPU device.
E2E_ENV = OBSCURA=$(CLI) OBSCURAD=$(BUILD)/obscurad BUILD=$(BUILD) \
          OBSCURA_CACHE_DIR=$(abspath $(BUILD))/e2e-cache
# `make e2e OBSCURA_BACKEND=cpu`: every script on the CPU device (obscura
# and obscurad read the variable where no --backend is given; gbuffer and
# the bakes rasterise on a GL context still).
ifneq ($(OBSCURA_BACKEND),)
E2E_ENV += OBSCURA_BACKEND=$(OBSCURA_BACKEND)
endif
E2E_ALONE = drain load output bakes hostile_http limits recover
E2E_ALL = $(wildcard tests/e2e/*.sh)
E2E_RUN = $(if $(E2E_ONLY),$(filter $(addprefix tests/e2e/,$(addsuffix .sh,$(E2E_ONLY))),$(E2E_ALL)),\
            $(filter-out $(addprefix tests/e2e/,$(addsuffix .sh,$(E2E_SKIP))),$(E2E_ALL)))

# the longest first, so that the two lanes end together
E2E_FIRST = $(addprefix tests/e2e/,$(addsuffix .sh,fuzz bake progcache dynamic deploy hostile_binary run))

e2e: $(CLI) $(E2E_DEPS)
	@$(E2E_ENV) E2E_ALONE="$(E2E_ALONE)" tests/run_e2e.sh $(filter $(E2E_FIRST),$(E2E_RUN)) \
	  $(filter-out $(E2E_FIRST),$(E2E_RUN))

# Every public header compiles alone, as C and as C++.
headers:
	@mkdir -p $(BUILD)/headers
	@for h in include/obscura/*.h protocol/http.h protocol/binary.h; do \
	  echo "#include \"$$h\"" > $(BUILD)/headers/t.c; \
	  $(CC) -I. -Iinclude -Wall -Wextra -Werror -std=c99 -c $(BUILD)/headers/t.c -o /dev/null || exit 1; \
	  cp $(BUILD)/headers/t.c $(BUILD)/headers/t.cpp; \
	  c++ -I. -Iinclude -Wall -Wextra -Werror -c $(BUILD)/headers/t.cpp -o /dev/null || exit 1; \
	done
	@echo "headers: each public header compiles alone as C and C++"

bench: deps
	@$(MAKE) --no-print-directory all $(BENCH) $(EXT_BENCH) $(UPSCALE) $(DAEMON_BENCH) $(DEEP_BENCH) \
	  $(if $(wildcard /usr/include/hwy/highway.h),$(HWY_BENCH) $(RAYS_HWY_BENCH))
	@BUILD=$(BUILD) bench/run.sh

# Quality against ground truth (bench/QUALITY.md, bench/quality/*.png): every
# method of bench/quality.sh's table on the Blender scenes of
# $(OBSCURA_SHARED_DATA) (default ../shared/data).
quality: deps
	@$(MAKE) --no-print-directory all $(QSTRIP)
	@BUILD=$(BUILD) bench/quality.sh

# The object masks against Cycles: the Blender room rendered twice with
# tools/blender_masks.py (one object hidden), each method with and without
# --occluders '!table' (bench/QUALITY.md, "Masks against a hidden-object
# Cycles render"); says it skipped where Debian's blender is not installed
# (tools/deps.sh --quality installs it; make test never needs it).
quality-masks: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bench/masks.sh cycles

# The multi-layer chain on rasterised deep G-buffers against Cycles, beside
# the flat chain (bench/QUALITY.md, "Deep input against Cycles").
quality-deep: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bench/deep_quality.sh

# The Blender scenes from cameras and at AO distances no other figure was
# measured on (four views a scene, fixed in the script), flat and deep,
# against obscura's Embree reference (bench/QUALITY.md, "Held-out views").
quality-heldout: deps
	@$(MAKE) --no-print-directory all
	@bench/heldout.py --obscura $(CLI) --shared $(or $(OBSCURA_SHARED_DATA),../shared/data)

# The baked vertices against the per-pixel obscurance reference
# (bench/BAKE.md, "Against a per-pixel reference"): the levels of
# $(OBSCURA_SHARED_DATA)/levels, sizes from bench/bake_quality.sh's
# environment (LEVELS, RAYS, SPP, CAMS, ...).
bake-quality: all $(QSTRIP)
	@OBSCURA=$(CLI) QSTRIP=$(QSTRIP) bench/bake_quality.sh

clean:
	rm -rf build out

# deploy/slurm's templates run by a live one-node Slurm on this machine
# (tests/farm/slurm.sh: installs slurm-wlm and munge as root when missing;
# skipped, saying why, where Slurm cannot run).  Not part of `make test`:
# CI (.ci/run) runs it after.
.PHONY: test-farm
test-farm: $(CLI)
	@BUILD=$(BUILD) OBSCURA=$(CLI) tests/farm/slurm.sh
