# tests/fuzz/: libFuzzer targets, built with clang (-fsanitize=fuzzer,
# address,undefined).  Included by the top Makefile; not part of `all`.
#
#   make fuzz        build $(BUILD)/fuzz/fuzz_binary, $(BUILD)/fuzz/fuzz_exr and
#                    $(BUILD)/fuzz/fuzz_files and refresh the seed corpus
#                    tests/fuzz/corpus/binary
#   $(BUILD)/fuzz/fuzz_binary -max_total_time=60 NEW_DIR tests/fuzz/corpus/binary
#   $(BUILD)/fuzz/fuzz_exr -max_total_time=60 NEW_DIR tests/data/damaged
#   $(BUILD)/fuzz/fuzz_files -max_total_time=60 NEW_DIR tests/fuzz/corpus/files
#                    (from the repository root; seeds: tests/fuzz/seed_files.sh)
#
# The protocol sources and the few core files they need are compiled here,
# with clang and the fuzzer's sanitizers, not taken from $(BUILD)/obj.
FUZZ_CC ?= clang
FUZZ_DIR := $(BUILD)/fuzz
FUZZ_CFLAGS := -O1 -g -std=c11 -D_DEFAULT_SOURCE -Wall -Wextra -Wno-missing-field-initializers \
               -Wno-string-plus-int -fno-omit-frame-pointer \
               -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_CPPFLAGS := -Iinclude -Icore -Iprotocol $(shell pkg-config --cflags libcjson OpenEXR 2>/dev/null)
FUZZ_LIBS := -lOpenEXRCore-3_1 $(shell pkg-config --libs libcjson 2>/dev/null) -lz -lm -lpthread
FUZZ_SRC := protocol/binary.c protocol/http.c core/status.c core/util.c core/image.c core/params.c \
            core/io/bytes.c core/io/channel_map.c core/io/presets.c core/io/exr_layers.c core/camera/request.c core/table.c \
            core/io/exr_msg.c core/pool.c
FUZZ_HDR := $(wildcard protocol/*.h include/obscura/*.h core/*.h core/*/*.h)
# The EXR readers (flat and deep) against OpenEXR's C library.
FUZZ_EXR_SRC := core/io/exr_read.c core/io/exr_deep.c core/io/exr_msg.c core/io/exr_parts.c core/io/exr_describe.c \
                core/io/exr_info.c core/camera/exr.c core/io/presets.c core/camera/request.c core/status.c core/util.c core/image.c core/io/channel_map.c \
                core/io/bytes.c core/params.c core/table.c core/pool.c core/io/crypto.c core/mask.c
FUZZ_EXR_LIBS := -lOpenEXRCore-3_1 $(shell pkg-config --libs libcjson 2>/dev/null) -lz -lm -lpthread
# The other files a user or a farm hands obscura (fuzz_files.c): camera
# JSON, object-mask selectors (against an EXR: the EXR readers), a .glb's
# own LODs (the scene they match loaded with assimp: level/load.c), the
# dynamic-AO model, the bake and bake-dynamic parts, bake-dynamic's
# regions file, the bakes' decorators file.  shard.c and
# dyn_shard.c are compiled for their part formats; their trace steps
# (never called) are dropped at link time (--gc-sections; start-stop-gc
# so that the coverage tables do not keep them).
FUZZ_FILES_SRC := core/camera/json.c core/level/lod_file.c core/level/load.c core/ground/assimp_check.c core/io/glb_read.c \
                  core/dynamic/dyn_model.c core/dynamic/dyn_fit.c core/dynamic/dyn_regions.c core/level/decor.c \
                  core/level/part.c core/level/sh.c core/level/sweep.c \
                  core/bake/shard.c core/dynamic/dyn_shard.c core/bake/params.c core/dynamic/dyn_params.c \
                  core/io/out_file.c $(FUZZ_EXR_SRC)
FUZZ_FILES_FLAGS := -ffunction-sections -fdata-sections -Wl,--gc-sections -Wl,-z,start-stop-gc
FUZZ_FILES_LIBS := $(FUZZ_EXR_LIBS) $(shell pkg-config --libs assimp 2>/dev/null)

.PHONY: fuzz fuzz-check
fuzz: fuzz-check $(FUZZ_DIR)/fuzz_binary $(FUZZ_DIR)/fuzz_exr $(FUZZ_DIR)/fuzz_files $(FUZZ_DIR)/corpus.stamp

fuzz-check:
	@command -v $(FUZZ_CC) >/dev/null 2>&1 || { \
	  echo "make fuzz: '$(FUZZ_CC)' not found; the fuzz targets need clang with libFuzzer" \
	       "(apt-get install clang, or make fuzz FUZZ_CC=/path/to/clang)" >&2; exit 1; }

$(FUZZ_DIR)/fuzz_binary: tests/fuzz/fuzz_binary.c $(FUZZ_SRC) $(FUZZ_HDR) | fuzz-check
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_SRC) -o $@ $(FUZZ_LIBS)

$(FUZZ_DIR)/fuzz_exr: tests/fuzz/fuzz_exr.c $(FUZZ_EXR_SRC) $(FUZZ_HDR) | fuzz-check
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_EXR_SRC) -o $@ $(FUZZ_EXR_LIBS)

$(FUZZ_DIR)/fuzz_files: tests/fuzz/fuzz_files.c $(FUZZ_FILES_SRC) $(FUZZ_DIR)/scene/assimp_read.o $(FUZZ_HDR) | fuzz-check
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CPPFLAGS) $(FUZZ_CFLAGS) $(FUZZ_FILES_FLAGS) -fsanitize=fuzzer $< $(FUZZ_FILES_SRC) $(FUZZ_DIR)/scene/assimp_read.o -o $@ $(FUZZ_FILES_LIBS) -lstdc++

$(FUZZ_DIR)/gen_corpus: tests/fuzz/gen_corpus.c $(FUZZ_SRC) $(FUZZ_HDR) | fuzz-check
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CPPFLAGS) $(FUZZ_CFLAGS) $< $(FUZZ_SRC) -o $@ $(FUZZ_LIBS)

$(FUZZ_DIR)/corpus.stamp: $(FUZZ_DIR)/gen_corpus
	@mkdir -p tests/fuzz/corpus/binary
	$(FUZZ_DIR)/gen_corpus tests/fuzz/corpus/binary
	@touch $@

# ---- fuzz_scene: the mesh and level loaders through assimp ---------------
# (tests/fuzz/fuzz_scene.c: obs_scene_load, obs_scene_load_baked,
# obs_bake_load, obs__bake_flatten).  assimp is not built with the
# sanitizers; its importers' own leaks are suppressed (tests/fuzz/scene.supp,
# which needs the slow unwinder).  assimp 5.2's importers themselves crash
# or ask for gigabytes on some mutated inputs (PLY, glTF): a long run goes
# on past those (-fork=1 -ignore_crashes=1 -ignore_ooms=1) and each artifact
# is then replayed to see whose code it stops in.
#   ASAN_OPTIONS=fast_unwind_on_malloc=0 LSAN_OPTIONS=suppressions=$PWD/tests/fuzz/scene.supp \
#     $(BUILD)/fuzz/fuzz_scene -max_len=65536 NEW_DIR tests/fuzz/corpus/scene
FUZZ_SCENE_SRC := core/ground/scene.c core/ground/assimp_check.c core/ground/baked.c core/io/glb_read.c core/level/load.c \
                  core/level/lod_file.c core/level/flatten.c core/status.c core/util.c
FUZZ_SCENE_CXX_SRC := core/ground/assimp_read.cpp
FUZZ_SCENE_LIBS := -lassimp $(shell pkg-config --libs libcjson 2>/dev/null) -lstdc++ -lm -lpthread

fuzz: $(FUZZ_DIR)/fuzz_scene

# assimp's C++ importer (core/ground/assimp_read.cpp), which level/load.c
# and ground/scene.c read through: linked by fuzz_files too.
$(FUZZ_DIR)/scene/assimp_read.o: $(FUZZ_SCENE_CXX_SRC) core/ground/assimp_read.h | fuzz-check
	@mkdir -p $(dir $@)
	$(FUZZ_CC)++ $(FUZZ_CPPFLAGS) $(filter-out -std=c11,$(FUZZ_CFLAGS)) -std=c++14 -fno-sanitize=vptr -c $< -o $@

$(FUZZ_DIR)/fuzz_scene: tests/fuzz/fuzz_scene.c $(FUZZ_SCENE_SRC) $(FUZZ_DIR)/scene/assimp_read.o $(FUZZ_HDR) | fuzz-check
	$(FUZZ_CC) $(FUZZ_CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_SCENE_SRC) $(FUZZ_DIR)/scene/assimp_read.o -o $@ $(FUZZ_SCENE_LIBS)
