/* Internal cross-file helpers of libobscura (obs__ prefix).  Not installed. */
#ifndef OBSCURA_INTERNAL_H
#define OBSCURA_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include "obscura/obscura.h"
#include "shaders/shared.h"

#if defined(__GNUC__)
#define OBS__PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define OBS__PRINTF(a, b)
#endif

/* Writes a formatted message into err (if non-NULL) and returns s
 * (obscura/status.h). */
#define obs__fail obs_status_fail

/* Milliseconds of CLOCK_MONOTONIC (for deadlines and stage times). */
double obs__now_ms(void);

/* The smallest memory limit (bytes) of this process's control groups,
 * read from PROC_CGROUP (/proc/self/cgroup) under SYS_CGROUP
 * (/sys/fs/cgroup), v1 and v2; 0 when none (core/memory.c). */
size_t obs__memory_cgroup_limit(const char *proc_cgroup, const char *sys_cgroup);

/* Overflow-checked size arithmetic: 0 on success, -1 when the product does
 * not fit in size_t (then *out is left alone). */
int obs__size_mul(size_t a, size_t b, size_t *out);
int obs__size_mul3(size_t a, size_t b, size_t c, size_t *out);

/* One allocation for n arrays made and freed together: array i has
 * bytes[i] bytes (0 counts as 1), each starts aligned for any type, all
 * are zero-filled; arr[i] gets array i's start.  arr[0] is the block
 * itself: free() it alone frees them all.  NULL (arr untouched) when
 * the sizes overflow or memory runs out. */
void *obs__alloc_arrays(size_t n, const size_t *bytes, void **arr);

/* Bytes of one plane's row (stride or packed) and pointer to pixel (x, y). */
size_t obs__plane_stride(const obs_plane *p, int width);
const float *obs__plane_px(const obs_plane *p, int width, int x, int y);

/* The key of --backend auto's kept measurement (device_auto.c): "HOST
 * VERSION METHOD THREADS", the host's blanks as '_'. */
void obs__device_key(const char *method, char *buf, size_t n);

/* Checks a G-buffer's sizes and planes before anything runs; the message
 * names the offending plane. */
obs_status obs__gbuffer_validate(const obs_gbuffer *gb, char err[OBS_ERR_LEN]);

/* 4x4 row-major matrices, column-vector convention. */
void obs__mat4_identity(float m[16]);
void obs__mat4_mul(const float a[16], const float b[16], float out[16]);
int obs__mat4_invert(const float m[16], float out[16]); /* -1 if singular */
void obs__mat4_transpose(const float m[16], float out[16]);
/* out = m * (x, y, z, w) */
void obs__mat4_apply(const float m[16], const float v[4], float out[4]);

/* A triangle's normal n = (p1 - p0) x (p2 - p0), unnormalised, and its
 * length |n| (twice the area); 0 (n zeroed) for a degenerate triangle:
 * zero area, a sliver whose normal float rounding decides
 * (|n| <= 1e-7 |e|^2), or a product beyond float.  The bake's flatten and
 * obs_scene_check take their degenerate faces from here. */
double obs__tri_normal(const float p0[3], const float p1[3], const float p2[3], float n[3]);

/* Sets parameter `name` of r to `value` (text, as obs_param_set) when r
 * leaves it unset (0): a preset's row, a parameter given explicitly
 * wins (--quality's presets, OBS_DEEP_GTAO_EXACT). */
void obs__params_fill(obs_params *r, const char *name, const char *value);

/* obs_params_resolve() of `in` with depth_mode and normal_space, where
 * `in` leaves them at 0, taken from the G-buffer's convention. */
void obs__params_for_gbuffer(const obs_params *in, const obs_gbuffer *gb, obs_params *out);

/* The camera a frame is computed with: the G-buffer's camera, overridden
 * by parameters (fov_y, world_to_camera) where they are set.  Fails with
 * NO_CAMERA when neither gives a projection. */
obs_status obs__camera_resolve(const obs_gbuffer *gb, const obs_params *p,
                               obs_camera *out, char err[OBS_ERR_LEN]);

/* Sample sets on the unit disk (VAO++ section 4.5), n = 2, 4, 8, 16, 32:
 * the checked-in output of the generator in samples_gen.c
 * (core/chain/sample_tables.c).  All five sets lie one after the other in one
 * table of OBS_SAMPLE_TABLE_LEN (x, y) pairs, the set of n starting at
 * pair n - 2: the layout of the shader's single uniform array (4.1). */
extern const float obs__sample_table[OBS_SAMPLE_TABLE_LEN][2];
/* n (x, y) pairs of the table; NULL unless n is 2, 4, 8, 16 or 32. */
const float *obs__samples(int n);

/* The generator behind the table, stopped at a stage (for the tests):
 * VAOPP is the whole of section 4.5 (= obs_samples_generate); POISSON the
 * rotation-aware Poisson-disk set alone, in the order its points were
 * placed; PLAIN a Poisson-disk set by the same method blind to the 9
 * rotations, in placing order (the rotation-unaware comparison). */
enum { OBS__SAMPLES_VAOPP, OBS__SAMPLES_POISSON, OBS__SAMPLES_PLAIN };
obs_status obs__samples_generate_ex(int n, int mode, float *xy);
/* Smallest distance between two of the n samples, or with rotations 1
 * between two points of the union of the set's 9 tile rotations. */
double obs__samples_min_distance(const float *xy, int n, int rotations);

/* Per-pixel rotation of the sample set: 3x3 tile of 9 uniform angles
 * (VAO++ section 4.5), computed from pixel coordinates. */
void obs__pixel_rotation(int x, int y, float *cos_a, float *sin_a);

/* The one image allocator (core/image.c): w x h x channels floats, the
 * size checked for overflow first.  Free with obs_image_free(). */
obs_status obs__image_alloc(obs_image *img, int w, int h, int channels, char err[OBS_ERR_LEN]);

/* Allocates the images of a result for `outputs` (OBS_OUTPUT_* bits). */
obs_status obs__alloc_result(obs_result *out, int w, int h, unsigned outputs,
                             char err[OBS_ERR_LEN]);

/* Reports through a context's log callback (no-op without a context or
 * a callback; core/log.c). */
void obs__log(obs_ctx *ctx, obs_log_level level, const char *fmt, ...)
    OBS__PRINTF(3, 4);
/* The same through a callback and its user pointer (NULL fn: no-op). */
void obs__logf(obs_log_fn fn, void *user, obs_log_level level, const char *fmt, ...)
    OBS__PRINTF(4, 5);

/* A growable byte buffer (core/io/bytes.c) behind obs_*_write_mem. */
typedef struct obs__membuf {
    unsigned char *data;
    size_t size, cap;
} obs__membuf;
/* Writes len bytes at offset, growing the buffer; -1 when out of memory. */
int obs__membuf_write(obs__membuf *m, uint64_t offset, const void *data, size_t len);
/* Moves the bytes into *out (the buffer is left empty). */
struct obs_bytes;
void obs__membuf_take(obs__membuf *m, struct obs_bytes *out);

#endif
