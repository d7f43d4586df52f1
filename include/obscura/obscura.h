/* obscura: headless ambient occlusion (VAO / VAO++) on a live OpenGL context.
 *
 * The core library computes; it never prints and never exits.  Every
 * function that can fail returns an obs_status and, where it takes one,
 * fills a caller-owned `char err[OBS_ERR_LEN]` with a message naming what
 * is wrong.  Logging goes through the callback installed on the context.
 *
 * Conventions (see README.md, "Input conventions"):
 *   - images are row-major, row 0 at the top, as OpenEXR stores them;
 *   - matrices are 4x4, row-major, column-vector convention
 *     (p_cam = M * p_world), as the camera JSON writes them;
 *   - view (camera) space is right-handed, the camera looks down -Z, +Y up;
 *   - AO is 1 where a point is unoccluded, 0 where fully occluded.
 */
#ifndef OBSCURA_H
#define OBSCURA_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/status.h"
#include "obscura/params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- logging ----------------------------------------------------------- */

typedef enum obs_log_level {
    OBS_LOG_ERROR,
    OBS_LOG_WARN,
    OBS_LOG_INFO,
    OBS_LOG_DEBUG
} obs_log_level;

typedef void (*obs_log_fn)(void *user, obs_log_level level, const char *msg);

/* ---- images and G-buffers ---------------------------------------------- */

/* One plane of float32 pixels, `channels` interleaved per pixel.
 * row_stride is in bytes; 0 means tightly packed. */
typedef struct obs_plane {
    const float *data;
    int channels;
    size_t row_stride;
} obs_plane;

/* Where the camera of a G-buffer came from. */
typedef enum obs_camera_source {
    OBS_CAMERA_NONE,
    OBS_CAMERA_EXR_HEADER, /* worldToCamera / worldToNDC attributes */
    OBS_CAMERA_JSON,       /* a camera JSON file */
    OBS_CAMERA_PARAMS      /* fov_y / world_to_camera parameters */
} obs_camera_source;

typedef struct obs_camera {
    float world_to_camera[16]; /* row-major, column-vector convention */
    float projection[16];      /* OpenGL clip space, row-major */
    int has_world_to_camera;   /* 0: world_to_camera is identity/unknown */
    int has_projection;        /* 0: projection unknown */
    obs_camera_source source;
} obs_camera;

/* A G-buffer: depth is required, normal (3 channels) and colour (4
 * channels, RGBA) are optional (data == NULL).  All planes share
 * width x height.
 *
 * The camera's projection covers the display window; the planes cover a
 * rectangle of it whose top-left pixel is (display_x, display_y) (an EXR's
 * data window).  display_width/height 0 mean "same as the planes". */
typedef struct obs_gbuffer {
    int width, height;
    int display_x, display_y;
    int display_width, display_height;
    obs_plane depth;
    obs_plane normal;
    obs_plane color;
    obs_camera camera;
    /* What the planes hold by the file's renderer convention (0: not
     * known); used where the parameters leave depth_mode or normal_space
     * at 0 (their default). */
    obs_depth_mode depth_mode;
    obs_normal_space normal_space;
    /* Optional world-space position pass (3 channels, data NULL when
     * absent): only to solve or check the camera, never drawn. */
    obs_plane position;
    /* Object masks (obscura/mask.h, obs_gbuffer_read_masks; data NULL when
     * not asked for), one float per pixel: receivers, the weight in [0, 1]
     * of a pixel's AO (1 - w (1 - AO) is returned; 0 leaves it at 1);
     * occluders, the weight of the surface at a pixel as an occluder of
     * the others; object_id, the object seen at a pixel (any float; with
     * it a sample counts only where it equals the shaded pixel's:
     * self_only). */
    obs_plane receivers;
    obs_plane occluders;
    obs_plane object_id;
} obs_gbuffer;

/* An image owned by the library: `channels` interleaved float32 values
 * per pixel, tightly packed, row 0 at the top. */
typedef struct obs_image {
    int width, height, channels;
    float *data;
} obs_image;

/* Frees the pixels and zeroes the struct; NULL-safe. */
void obs_image_free(obs_image *img);

/* ---- size limits ------------------------------------------------------- */

typedef struct obs_limits {
    int max_width;      /* 0 -> 16384 */
    int max_height;     /* 0 -> 16384 */
    uint64_t max_pixels; /* 0 -> max_width * max_height */
    int threads;        /* EXR decode threads; 0 -> CPUs online, up to 8 (at
                           most 64, and one for every 4 chunks of a part) */
} obs_limits;

/* Checks width x height against the limits (zeroed limits = defaults). */
obs_status obs_check_size(const obs_limits *lim, int64_t width, int64_t height,
                          char err[OBS_ERR_LEN]);

/* ---- threads ----------------------------------------------------------- */

/* The process's thread limit (obscura --threads, obscurad --render-threads,
 * OBSCURA_THREADS): every worker pool of the library (bake and reference
 * ray tracing, EXR decode and the rest) runs at most n threads, and
 * llvmpipe's rasterizer n: LP_NUM_THREADS is set to n unless the
 * environment has it already (Mesa reads it when a context is created).
 * It may set an environment variable: call it first, before contexts and
 * threads.  n in [1, 64]; 0 lifts the limit. */
obs_status obs_threads_set(int n, char err[OBS_ERR_LEN]);

typedef struct obs_threads_info {
    int limit;              /* obs_threads_set's n; 0: none */
    int pool;               /* threads a worker pool starts: the limit, else the cores (at most 64) */
    int llvmpipe;           /* LP_NUM_THREADS as llvmpipe reads it; -1: unset (one per core) */
    int llvmpipe_from_user; /* 1: LP_NUM_THREADS came from the environment (kept over the limit) */
} obs_threads_info;
void obs_threads_get(obs_threads_info *out);

/* ---- GL context -------------------------------------------------------- */

typedef enum obs_backend {
    OBS_BACKEND_AUTO,
    OBS_BACKEND_EGL_DEVICE,
    OBS_BACKEND_EGL_SURFACELESS,
    OBS_BACKEND_OSMESA,
    OBS_BACKEND_COUNT
} obs_backend;

/* "auto", "egl-device", "egl-surfaceless", "osmesa". */
const char *obs_backend_name(obs_backend b);
/* Parses a backend name; returns OBS_INVALID_ARGUMENT for unknown names. */
obs_status obs_backend_parse(const char *name, obs_backend *out);

typedef struct obs_ctx obs_ctx;

typedef struct obs_ctx_desc {
    obs_backend backend; /* AUTO tries egl-device, egl-surfaceless, osmesa */
    int debug;           /* install a KHR_debug callback (logs GL messages) */
    obs_log_fn log;      /* may be NULL */
    void *log_user;
    /* The program cache's folder (obs_cache_dir_default gives the usual
     * one); NULL or "": no cache.  Linked programs are kept there as the
     * driver's program binaries, and Mesa's shader cache is pointed there
     * too (MESA_SHADER_CACHE_DIR, unless set; on in this process): create
     * the first context before starting threads that read the
     * environment.  A folder that cannot be written is read-only; one
     * that cannot be read or made is no cache (one log line each). */
    const char *cache_dir;
} obs_ctx_desc;

typedef struct obs_ctx_info {
    obs_backend backend;
    const char *gl_version; /* owned by the context */
    const char *gl_vendor;
    const char *gl_renderer;
    const char *cache_dir;  /* the program cache in use, owned by the context; NULL: none */
    int cache_writable;     /* 0: programs are loaded from it, none is stored */
    unsigned long programs_compiled; /* built from source by this context */
    unsigned long programs_loaded;   /* loaded from the program cache */
    unsigned long programs_rejected; /* cache entries found unusable (damaged,
                                        another driver's), rebuilt */
} obs_ctx_info;

/* The program cache's folder: `given` when not NULL (a --cache-dir flag),
 * else $OBSCURA_CACHE_DIR when set, else $XDG_CACHE_HOME/obscura, else
 * $HOME/.cache/obscura; written to buf (n bytes) and returned.  "" (given
 * or the variable set to it) means no cache; "" with why filled (when
 * not NULL) means no folder could be found. */
const char *obs_cache_dir_default(const char *given, char *buf, size_t n, char why[OBS_ERR_LEN]);

/* Creates the GL context and makes it current on the calling thread; only
 * that thread may use the context afterwards.  Caller frees with
 * obs_ctx_destroy(). */
obs_status obs_ctx_create(const obs_ctx_desc *desc, obs_ctx **out,
                          char err[OBS_ERR_LEN]);
void obs_ctx_destroy(obs_ctx *ctx);
void obs_ctx_get_info(const obs_ctx *ctx, obs_ctx_info *info);

/* --backend auto's choice of device (README, Backends). */
typedef struct obs_device_choice {
    int cpu;             /* 1: the CPU device (obs_run_cpu), 0: a GL context */
    obs_backend backend; /* with cpu 0: EGL_DEVICE (a GPU was found) or AUTO */
    int measured, cached;
    double cpu_ms, gl_ms; /* the measurement's medians; -1: none */
    char why[256];        /* one line saying what was chosen and why */
} obs_device_choice;

/* With measure_now: an EGL GPU device when there is one; else the
 * device kept for this machine, version, method (params' method, NULL:
 * the defaults) and thread count in cache_dir/devices.txt; else the
 * faster of the CPU device and the software GL context on a synthetic
 * 960x540 frame of the chain, measured now (about a second) and kept
 * there; the CPU device when no GL context can be created.  Without
 * measure_now the kept choice is read; when none is kept, an EGL GPU
 * device when there is one, else the CPU device (faster than llvmpipe on
 * every method: bench/RESULTS.md), nothing measured. */
obs_status obs_device_choose(const char *cache_dir, const obs_params *params, int measure_now,
                             obs_device_choice *out, char err[OBS_ERR_LEN]);

/* ---- running the AO chain ---------------------------------------------- */

enum {
    OBS_OUTPUT_AO = 1,          /* one channel, 1 = unoccluded */
    OBS_OUTPUT_COMPOSITE = 2,   /* RGBA: colour x AO (x bleed with bleeding) */
    OBS_OUTPUT_SAMPLE_COUNT = 4, /* debug: one channel, the samples each pixel
                                    took (VAO++ 4.1); 0 for background and
                                    for greedily culled pixels (4.2) */
    OBS_OUTPUT_CULL_MASK = 8,    /* debug: one channel, 1 where the culling
                                    pre-pass (VAO++ 4.2) made the pixel a
                                    culling candidate, else 0 */
    OBS_OUTPUT_BLEED = 16,       /* RGB: the colour-bleed term (VAO++ 4.7),
                                    (1,1,1) where there is none or bleeding
                                    is off */
    OBS_OUTPUT_LUMINANCE = 32,   /* debug: one channel, the luminance-
                                    sensitivity factor of VAO++ eq 3 (4.3):
                                    1 keeps the pixel's occlusion, 0 removes
                                    it; 1 everywhere when it is off */
    OBS_OUTPUT_MULTIBOUNCE = 64, /* RGB: the AO through the multi-bounce fit
                                    of the colour plane's albedo (parameter
                                    multibounce); not filled without a
                                    colour plane */
    OBS_OUTPUT_DEEP = 128,       /* deep input only, a request option of
                                    obscura ao: the AO of every kept node as
                                    a deep EXR (obs_deep_ao_nodes, deep.h);
                                    obs_run ignores it */
    OBS_OUTPUT_BENT = 512        /* RGB: the bent normal (the mean unoccluded
                                    direction, cosine-weighted) in the
                                    normals' space, unit length, 0 on the
                                    background; methods with one (gtao);
                                    others leave it out */
};

typedef struct obs_result {
    obs_image ao;           /* filled when OBS_OUTPUT_AO was asked */
    obs_image composite;    /* filled when OBS_OUTPUT_COMPOSITE was asked */
    obs_image sample_count; /* filled when OBS_OUTPUT_SAMPLE_COUNT was asked */
    obs_image cull_mask;    /* filled when OBS_OUTPUT_CULL_MASK was asked */
    obs_image bleed;        /* filled when OBS_OUTPUT_BLEED was asked */
    obs_image luminance;    /* filled when OBS_OUTPUT_LUMINANCE was asked */
    obs_image bent;         /* RGB; filled when OBS_OUTPUT_BENT was asked and
                               the method has one */
    obs_image multibounce;  /* RGB; filled when OBS_OUTPUT_MULTIBOUNCE was asked,
                               or multibounce is on with the AO, and the
                               G-buffer has a colour plane */
    /* After obs_result_combine_baked: the chain's own AO (ao is then the
     * combination) and the baked channel it was combined with. */
    obs_image ao_screen, ao_baked;
} obs_result;

/* Runs the AO chain on the context's thread.  `params` may be NULL or
 * zeroed for defaults.  The G-buffer's camera is used unless the params
 * carry one (fov_y / world_to_camera).  Caller frees with
 * obs_result_free(). */
obs_status obs_run(obs_ctx *ctx, const obs_gbuffer *gb, const obs_params *params,
                   unsigned outputs, obs_result *out, char err[OBS_ERR_LEN]);

/* The same computation on the CPU device (`--backend cpu`): the CPU
 * twins of the GL passes, each pass in bands or tiles on the worker pool
 * (every core), the AO and the blur in SIMD lanes; the same bytes for
 * any thread count.  No GL context.  Same ownership as obs_run(). */
obs_status obs_run_cpu(const obs_gbuffer *gb, const obs_params *params,
                       unsigned outputs, obs_result *out, char err[OBS_ERR_LEN]);

/* What obs_run_cpu_opts takes besides the frame (zeroed: obs_run_cpu). */
typedef struct obs_cpu_options {
    /* the frame's messages (the channel and camera notes a GL context's
     * log gets, such as "reconstructing normals from depth"); NULL:
     * dropped */
    obs_log_fn log;
    void *log_user;
    /* seconds: the run stops with OBS_DEADLINE once the chain has taken
     * longer (the clock read between passes and between the AO pass's
     * tiles, so at most one tile past it); 0: no deadline */
    double deadline;
    /* polled where the deadline is read, from the worker pool's threads
     * (possibly several at once); a nonzero return stops the run with
     * OBS_CANCELLED (obscurad's drain: a frame nobody waits for any
     * more); NULL: never */
    int (*cancel)(void *user);
    void *cancel_user;
    /* bytes the chain's planes may take (about 56 a pixel at the default
     * parameters): a frame that needs more runs in bands of rows, each
     * holding its rows and the halo its samples reach (the same result,
     * the input and the result still whole); 0: a quarter of the
     * usable memory (obs_cpu_memory_usable) */
    size_t max_memory;
    /* > 0: bands of this many rows whatever the frame's size (tests) */
    int band_rows;
    /* what set max_memory, as the warning of a band over the budget
     * (through log) names it, e.g. "--max-memory 256 MiB"; NULL: "the
     * memory budget", with the default's description where max_memory
     * is 0 */
    const char *max_memory_name;
} obs_cpu_options;

obs_status obs_run_cpu_opts(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                            obs_result *out, const obs_cpu_options *opt, char err[OBS_ERR_LEN]);

/* The memory budget of opt (NULL: the default): opt->max_memory, else a
 * quarter of obs_cpu_memory_usable(). */
size_t obs_cpu_memory_budget(const obs_cpu_options *opt);

/* The memory this process may use, in bytes (what the default budget is a
 * quarter of): the usable memory (obs_cpu_memory_usable), or its control group's
 * memory limit when lower (cgroup v2 memory.max, v1
 * memory.limit_in_bytes: a Slurm job, a container, a systemd unit with
 * MemoryMax); 0 when not known. */
size_t obs_cpu_memory_usable(void);

/* The default budget as the CLI and the daemon say it: "N MiB (default:
 * a quarter of G GiB usable; --max-memory MIB sets it)". */
void obs_cpu_memory_default_text(char *buf, size_t n);

/* A frame that is never whole in memory, on the CPU device: run in bands
 * of rows as obs_run_cpu_opts runs a frame over its memory budget (the
 * same result, byte for byte), each band's rows of the G-buffer asked of
 * `in`, the result's rows handed to `out` in order.
 *   frame: the frame's size, windows, camera and conventions, its planes'
 *     data NULL and their channels set (1, 3 for normals, 4 for colour
 *     when it has them: obs_gbuffer_rows_open's meta->gb); no object masks
 *     (OBS_UNSUPPORTED).
 *   in(user, y0, y1, rows, err): *rows is the frame with its planes' data
 *     at row y0, holding rows [y0, y1) (valid until the next call).  The
 *     depth is read once ahead of the bands (the samples' reach, a few
 *     hundred rows at a time), then each band's rows with its halo.
 *   out(user, y0, y1, res, err): rows [y0, y1) of the result, images of
 *     y1 - y0 rows (valid during the call).
 * A status other than OBS_OK from either stops the run and is returned. */
typedef obs_status (*obs_rows_in_fn)(void *user, int y0, int y1, obs_gbuffer *rows, char err[OBS_ERR_LEN]);
typedef obs_status (*obs_rows_out_fn)(void *user, int y0, int y1, const obs_result *rows,
                                      char err[OBS_ERR_LEN]);
obs_status obs_run_cpu_rows(const obs_gbuffer *frame, obs_rows_in_fn in, obs_rows_out_fn out, void *user,
                            const obs_params *params, unsigned outputs, const obs_cpu_options *opt,
                            char err[OBS_ERR_LEN]);

void obs_result_free(obs_result *r);

/* Baked and screen-space AO in one frame: r->ao (the chain's, 1 channel)
 * combined per pixel with `baked` (1 channel of the same size: a baked AO
 * channel of the G-buffer, obscura gbuffer's _AO) by the parameter
 * baked_combine: product b x s (default) or min(b, s).  Baked values are
 * clamped to [0, 1]; a non-finite one counts as 1 (no baked value).
 * Afterwards r->ao is the combination, r->ao_screen the chain's AO,
 * r->ao_baked the baked values used, and the composite (when r has one)
 * is the colour times the combination: its RGB scaled by combination /
 * screen-space AO, as the composite is linear in the AO.  Fails with
 * OBS_INVALID_ARGUMENT when r has no AO, or the sizes differ. */
obs_status obs_result_combine_baked(obs_result *r, const obs_image *baked,
                                    const obs_params *params, char err[OBS_ERR_LEN]);

/* The work a frame asks for, in samples: width x height x the samples per
 * pixel of its method (vaopp, vao: samples; hemisphere:
 * hemisphere_samples; angle: 2 x angle_pairs; hbao: hbao_directions x
 * hbao_steps; gtao: 2 x gtao_slices x gtao_steps), times deep_layers squared for deep input (every node's
 * samples test every node at their pixel; 0 or 1: a flat frame).  A
 * measure to refuse frames by before running them (obscurad --max-cost);
 * parameters as obs_run takes them (NULL: defaults). */
unsigned long long obs_frame_cost(const obs_params *params, int width, int height,
                                  int deep_layers);

/* ---- what the context keeps between frames ----------------------------- */

/* Bytes of texture storage the context keeps between frames: the chain's
 * targets of the last frame size and deep input's of the last size and
 * node count (reused by the next frame of that size; programs are not
 * counted). */
unsigned long long obs_ctx_kept_bytes(const obs_ctx *ctx);

/* Releases the kept targets when they hold more than budget bytes (0:
 * always); the next frame allocates them again.  Programs stay.  Call
 * on the context's thread, e.g. when idle. */
obs_status obs_ctx_trim(obs_ctx *ctx, unsigned long long budget, char err[OBS_ERR_LEN]);

/* The CPU device's twins of these: the bytes of the one block of planes
 * it keeps for the next frame (process-wide), and their release when
 * more than budget (0: always).  Any thread. */
unsigned long long obs_cpu_kept_bytes(void);
void obs_cpu_trim(unsigned long long budget);

/* ---- a deadline on each frame's GL work -------------------------------- */

/* Each following obs_run and obs_deep_run stops with OBS_DEADLINE when
 * its GL work has taken longer than `seconds` since the call began (0:
 * no deadline, the default).  With a deadline the AO pass, the one whose
 * cost grows with the samples, is drawn in bands of rows (scissored),
 * each waited for (glFinish) and the clock checked between them, so the
 * frame stops at most one band past the deadline; the output is the same
 * as without bands. */
obs_status obs_ctx_set_deadline(obs_ctx *ctx, double seconds, char err[OBS_ERR_LEN]);

/* ---- per-pass GPU timings ---------------------------------------------- */

/* The passes of obs_run, in order.  UPLOAD and READBACK are the texture
 * transfers of the G-buffer and of the results. */
typedef enum obs_pass {
    OBS_PASS_UPLOAD,
    OBS_PASS_PREP,
    OBS_PASS_DOWNSAMPLE, /* ao_resolution half: the prep pass straight to half size (no full prep) */
    OBS_PASS_CULL,
    OBS_PASS_AO,
    OBS_PASS_BLUR,
    OBS_PASS_UPSAMPLE,   /* ao_resolution half: the AO back to full size */
    OBS_PASS_FINISH,    /* luminance sensitivity; ao_definition rays' conversion without blur */
    OBS_PASS_COMPOSITE,
    OBS_PASS_READBACK,
    OBS_PASS_COUNT
} obs_pass;

/* "upload", "prep", "downsample", "cull", "ao", "blur", "upsample",
 * "finish", "composite", "readback". */
const char *obs_pass_name(obs_pass p);

typedef struct obs_pass_times {
    double ms[OBS_PASS_COUNT]; /* GL time of each pass; -1: it did not run */
    double total_ms;           /* sum of the passes that ran */
} obs_pass_times;

/* Turns per-pass timing on or off for the following obs_run calls: each
 * pass is bracketed by a GL_TIME_ELAPSED query (GL 3.3 timer queries),
 * read back when the frame ends.  Off by default: reading the queries
 * waits for the GPU. */
obs_status obs_ctx_set_timing(obs_ctx *ctx, int on, char err[OBS_ERR_LEN]);

/* The times of the last obs_run with timing on; 0 when there is none. */
int obs_ctx_last_times(const obs_ctx *ctx, obs_pass_times *out);

/* ---- sample sets --------------------------------------------------------- */

/* Runs the VAO++ sample generator (section 4.5: rotation-aware Poisson
 * disk, best permutation of rotations, z-order) for n = 2, 4, 8, 16 or 32
 * points, writing n (x, y) pairs on the unit disk to xy.  Deterministic
 * (fixed seed); its output is the table the library uses.  Takes about
 * 0.1 s for n = 32. */
obs_status obs_samples_generate(int n, float *xy);

/* The library's table for n = 2, 4, 8, 16, 32 (n pairs); NULL otherwise. */
const float *obs_samples_table(int n);

#ifdef __cplusplus
}
#endif

#endif
