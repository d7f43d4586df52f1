/* Deep input: the deep scanline reader (fixture written by
 * tools/deep_fixture.cpp, damaged files), the list compression of OITAO
 * III-B (eq 5 against a hand-computed case), multi-layer AO (a hidden
 * occluder seen only in a deeper layer, with VAO++'s line samples and
 * with method hemisphere's point samples), opacity (eqs 1-4), the methods
 * deep input refuses, the GL pass against its CPU twin, and the three deep EXRs of OpenEXR's
 * LowResLeftView set when ../shared is present. */
#include "testutil.h"

#include <dirent.h>
#include <math.h>

#include "obscura/deep.h"
#include "deep/deep_internal.h"
#include "context.h"
#include "methods/hemisphere.h"
#include "methods/methods.h"

#define FIXTURE TESTDATA "/deep_small.exr"

static const float *px_samples(const obs_deep_image *d, int x, int y, int *n)
{
    size_t i = (size_t)y * d->width + x;
    *n = (int)(d->offset[i + 1] - d->offset[i]);
    return d->samples + d->offset[i] * OBS_DEEP_CH;
}

/* ---- reader ----------------------------------------------------------------- */

/* The fixture's layout (tools/deep_fixture.cpp), sorted front to back. */
static void test_read_fixture(void **state)
{
    (void)state;
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    int deep = 0;
    assert_int_equal(obs_exr_is_deep(FIXTURE, &deep, err), OBS_OK);
    assert_int_equal(deep, 1);
    if (obs_deep_read_exr(FIXTURE, NULL, &d, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(d.width, 48);
    assert_int_equal(d.height, 32);
    assert_true(d.has_zback && d.has_alpha && d.has_color && !d.has_normal);
    assert_true(d.camera.has_projection);
    assert_int_equal((int)d.offset[48 * 32], 1536 + 640 + 256 + 10);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 48; x++) {
            int n, want = 1 + (x >= 16 && y >= 12) + (x >= 8 && x < 24 && y >= 8 && y < 24) +
                          (x == 0 && y == 0) * 10;
            const float *s = px_samples(&d, x, y, &n);
            assert_int_equal(n, want);
            for (int k = 1; k < n; k++) /* sorted */
                assert_true(s[k * OBS_DEEP_CH] >= s[(k - 1) * OBS_DEEP_CH]);
            const float *back = s + (n - 1) * OBS_DEEP_CH;
            assert_float_equal(back[OBS_DEEP_Z], 8.0f, 1e-6);
            assert_float_equal(back[OBS_DEEP_B], 0.6f, 1e-3);
            assert_float_equal(back[OBS_DEEP_ZBACK], 8.0f, 1e-6);
            if (x >= 8 && x < 24 && y >= 8 && y < 24 && !(x == 0 && y == 0)) {
                assert_float_equal(s[OBS_DEEP_Z], 4.0f, 1e-6);
                assert_float_equal(s[OBS_DEEP_A], 0.5f, 1e-3);
                assert_float_equal(s[OBS_DEEP_R], 0.5f, 1e-3);
            }
        }
    int n;
    const float *s = px_samples(&d, 0, 0, &n);
    for (int k = 0; k < 10; k++)
        assert_float_equal(s[k * OBS_DEEP_CH], 1.0f + 0.1f * (float)k, 1e-5);

    /* the same from memory */
    size_t len;
    unsigned char *buf = obs_test_slurp(FIXTURE, &len);
    obs_deep_image m;
    assert_int_equal(obs_deep_read_exr_mem(buf, len, NULL, &m, err), OBS_OK);
    assert_int_equal(memcmp(m.offset, d.offset, (48 * 32 + 1) * sizeof *d.offset), 0);
    assert_int_equal(memcmp(m.samples, d.samples, d.offset[48 * 32] * OBS_DEEP_CH * sizeof(float)), 0);
    obs_deep_free(&m);
    free(buf);
    obs_deep_free(&d);

    /* a flat file is no deep input */
    assert_int_equal(obs_exr_is_deep(TESTDATA "/room_small.exr", &deep, err), OBS_OK);
    assert_int_equal(deep, 0);
    assert_int_equal(obs_deep_read_exr(TESTDATA "/room_small.exr", NULL, &d, err), OBS_UNSUPPORTED);
    assert_non_null(strstr(err, "no deep part"));
}

/* The size limits apply before anything is allocated. */
static void test_read_limits(void **state)
{
    (void)state;
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    obs_limits lim = {.max_width = 32};
    assert_int_equal(obs_deep_read_exr(FIXTURE, &lim, &d, err), OBS_TOO_LARGE);
    assert_true(err[0] != '\0');
    assert_null(d.samples);
}

static void check_status(const char *what, obs_status st, const char *err)
{
    if (st != OBS_OK && err[0] == '\0')
        fail_msg("%s: failed (%s) without a message", what, obs_status_name(st));
    if (st != OBS_OK && st != OBS_BAD_FILE && st != OBS_UNSUPPORTED && st != OBS_MISSING_CHANNEL &&
        st != OBS_TOO_LARGE && st != OBS_NO_MEMORY && st != OBS_IO)
        fail_msg("%s: unexpected status %s (%s)", what, obs_status_name(st), err);
}

static void read_any(const char *what, const unsigned char *buf, size_t len, int *ok)
{
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    obs_status st = obs_deep_read_exr_mem(buf, len, NULL, &d, err);
    check_status(what, st, err);
    if (st == OBS_OK) {
        size_t npx = (size_t)d.width * d.height;
        for (size_t i = 0; i < npx; i++)
            assert_true(d.offset[i + 1] >= d.offset[i]);
        (*ok)++;
    } else {
        assert_null(d.samples);
    }
    obs_deep_free(&d);
}

/* The fixture cut short at every length and with bytes of its chunks
 * (count tables, sample data) overwritten: a status, never a crash. */
static void test_read_damaged_fixture(void **state)
{
    (void)state;
    size_t len;
    unsigned char *buf = obs_test_slurp(FIXTURE, &len);
    unsigned char *bad = malloc(len);
    int ok = 0;
    char what[64];
    for (size_t cut = 0; cut < len; cut += cut < 600 ? 7 : 97) {
        snprintf(what, sizeof what, "fixture cut at %zu", cut);
        read_any(what, buf, cut ? cut : 1, &ok);
    }
    assert_int_equal(ok, 0);
    unsigned seed = 12345;
    for (int t = 0; t < 300; t++) {
        memcpy(bad, buf, len);
        for (int k = 0; k < 4; k++) {
            seed = seed * 1103515245u + 12345u;
            size_t at = 300 + (seed >> 8) % (len - 300);
            seed = seed * 1103515245u + 12345u;
            bad[at] = (unsigned char)(seed >> 16);
        }
        snprintf(what, sizeof what, "fixture damaged, trial %d", t);
        read_any(what, bad, len, &ok);
    }
    free(bad);
    free(buf);
}

static void run_dir(const char *dir, int *files)
{
    DIR *dp = opendir(dir);
    struct dirent *e;
    if (!dp)
        return;
    while ((e = readdir(dp))) {
        char path[1024];
        if (e->d_name[0] == '.' || strstr(e->d_name, ".rst"))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        obs_deep_image d;
        char err[OBS_ERR_LEN] = "";
        obs_status st = obs_deep_read_exr(path, NULL, &d, err);
        check_status(path, st, err);
        obs_deep_free(&d);
        size_t len;
        unsigned char *buf = obs_test_slurp(path, &len);
        int ok = 0;
        if (len > 0)
            read_any(path, buf, len, &ok);
        free(buf);
        (*files)++;
    }
    closedir(dp);
}

/* OpenEXR's damaged files (fuzzer cases, several deep): rejected with a
 * message or read, never a crash, hang or leak. */
static void test_read_damaged_files(void **state)
{
    (void)state;
    char dir[512];
    int files = 0;
    run_dir(TESTDATA "/damaged", &files);
    assert_true(files > 10);
    snprintf(dir, sizeof dir, "%s/openexr-images/Damaged", obs_test_shared());
    run_dir(dir, &files);
}

/* ---- list compression (OITAO III-B, eq 5) --------------------------------- */

static void sample(float *s, float z, float a)
{
    memset(s, 0, OBS_DEEP_CH * sizeof(float));
    s[OBS_DEEP_Z] = s[OBS_DEEP_ZBACK] = z;
    s[OBS_DEEP_A] = a;
}

/* m = 2, z already in [0, 1], inserted out of order:
 *   z 0.6 a 0.5 -> a (1 - z) = 0.20
 *   z 0.1 a 0.1 ->             0.09
 *   z 0.5 a 0.9 ->             0.45
 * After the third insertion the array is [0.1, 0.5, 0.6]; eq 5 over all
 * three drops 0.1 (0.09), keeping [0.5, 0.6]; over the back half (j >=
 * m / 2 = 1) it drops 0.6 (0.20 < 0.45), keeping [0.1, 0.5]. */
static void test_compress_eq5(void **state)
{
    (void)state;
    float in[3 * OBS_DEEP_CH], out[OBS_DEEP_MAX_LAYERS * OBS_DEEP_CH];
    sample(in, 0.6f, 0.5f);
    sample(in + OBS_DEEP_CH, 0.1f, 0.1f);
    sample(in + 2 * OBS_DEEP_CH, 0.5f, 0.9f);
    assert_int_equal(obs_deep_compress_list(in, 3, 2, 0, 0.0f, 1.0f, out), 2);
    assert_float_equal(out[OBS_DEEP_Z], 0.5f, 0);
    assert_float_equal(out[OBS_DEEP_CH + OBS_DEEP_Z], 0.6f, 0);
    assert_int_equal(obs_deep_compress_list(in, 3, 2, 1, 0.0f, 1.0f, out), 2);
    assert_float_equal(out[OBS_DEEP_Z], 0.1f, 0);
    assert_float_equal(out[OBS_DEEP_CH + OBS_DEEP_Z], 0.5f, 0);
    /* fewer samples than nodes: kept, sorted */
    assert_int_equal(obs_deep_compress_list(in, 2, 4, 0, 0.0f, 1.0f, out), 2);
    assert_float_equal(out[OBS_DEEP_Z], 0.1f, 0);

    /* m = 4, depths normalised over 2..12 (z = (Z - 2) / 10):
     *   Z 2 a .2 -> .20, 4 a 1 -> .80, 7 a .1 -> .05, 9 a .6 -> .18,
     *   12 a 1 -> 0 (dropped on the 5th insertion), 5 a .4 -> .28; the
     *   6th leaves [2, 4, 5, 7, 9], where 7 (.05) goes: [2, 4, 5, 9]. */
    float in6[6 * OBS_DEEP_CH];
    const float Z[6] = {2, 4, 7, 9, 12, 5}, A[6] = {.2f, 1, .1f, .6f, 1, .4f};
    for (int k = 0; k < 6; k++)
        sample(in6 + k * OBS_DEEP_CH, Z[k], A[k]);
    assert_int_equal(obs_deep_compress_list(in6, 6, 4, 0, 2.0f, 12.0f, out), 4);
    const float want[4] = {2, 4, 5, 9};
    for (int k = 0; k < 4; k++)
        assert_float_equal(out[k * OBS_DEEP_CH + OBS_DEEP_Z], want[k], 0);

    /* the paper's criterion (OITAO III-B) over the view frustum: the
     * fixture's pixel (0, 0) holds ten samples of alpha 0.3 at Z 1 .. 1.9
     * and the opaque wall at 8, the image's farthest depth.  Its camera has
     * the default clip range 0.1 .. 1000, so z = (Z - 0.1) / 999.9: the
     * wall scores 1 - 0.0079 = 0.992, each transparent sample about 0.3
     * (falling with depth).  The opaque wall is kept, and of the
     * transparent samples the nearest: m = 4 keeps Z 1, 1.1, 1.2 and 8.
     * (Normalised over the image's own range, 1 .. 8, the wall would
     * score 0 and be dropped first.) */
    obs_deep_image d;
    obs_deep_layers l;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_deep_read_exr(FIXTURE, NULL, &d, err), OBS_OK);
    assert_int_equal(obs_deep_compress(&d, 4, 0, &l, err), OBS_OK);
    assert_float_equal(l.zmin, 0.1f, 1e-4);
    assert_float_equal(l.zmax, 1000.0f, 1.0);
    assert_int_equal(l.count[0], 4);
    size_t npx = 48 * 32;
    const float keep[4] = {1.0f, 1.1f, 1.2f, 8.0f};
    for (int k = 0; k < 4; k++)
        assert_float_equal(l.node[(size_t)k * npx * OBS_DEEP_CH + OBS_DEEP_Z], keep[k], 1e-5);
    obs_deep_layers_free(&l);

    /* the farthest sample of a list is not dropped for being the farthest:
     * near 1, far 10, z = (Z - 1) / 9:
     *   Z 2 a .2 -> .2 (1 - 1/9) = .178, Z 4 a .3 -> .3 (1 - 3/9) = .2,
     *   Z 6 a 1 -> 1 - 5/9 = .444: m = 2 drops Z 2, keeps [4, 6]
     * (over the list's own range 2 .. 6 the wall would score 0 and go);
     * at the far plane itself, the paper's initial depth of 1, a node
     * scores 0 whatever its opacity and goes first: [2, 4] */
    float lst[3 * OBS_DEEP_CH];
    sample(lst, 2.0f, 0.2f);
    sample(lst + OBS_DEEP_CH, 4.0f, 0.3f);
    sample(lst + 2 * OBS_DEEP_CH, 6.0f, 1.0f);
    assert_int_equal(obs_deep_compress_list(lst, 3, 2, 0, 1.0f, 10.0f, out), 2);
    assert_float_equal(out[OBS_DEEP_Z], 4.0f, 0);
    assert_float_equal(out[OBS_DEEP_CH + OBS_DEEP_Z], 6.0f, 0);
    sample(lst + 2 * OBS_DEEP_CH, 10.0f, 1.0f);
    assert_int_equal(obs_deep_compress_list(lst, 3, 2, 0, 1.0f, 10.0f, out), 2);
    assert_float_equal(out[OBS_DEEP_Z], 2.0f, 0);
    assert_float_equal(out[OBS_DEEP_CH + OBS_DEEP_Z], 4.0f, 0);
    d.camera.has_projection = 0; /* no projection: the parameters' default 0.1 .. 1000 */
    assert_int_equal(obs_deep_compress(&d, 4, 0, &l, err), OBS_OK);
    assert_float_equal(l.zmin, 0.1f, 1e-6);
    assert_float_equal(l.zmax, 1000.0f, 1e-3);
    obs_deep_layers_free(&l);
    obs_deep_free(&d);
}

/* ---- multi-layer AO ------------------------------------------------------ */

/* A synthetic A-buffer: w x h, up to 3 samples per pixel. */

static void synth_init(obs_deep_image *d, int w, int h)
{
    memset(d, 0, sizeof *d);
    d->width = w;
    d->height = h;
    d->offset = calloc((size_t)w * h + 1, sizeof *d->offset);
    d->samples = calloc((size_t)w * h * 3, OBS_DEEP_CH * sizeof(float));
    d->has_alpha = 1;
    d->has_color = 1;
}

static void synth_add(obs_deep_image *d, int x, int y, float z, float a)
{
    /* pixels are filled in order: each call appends to the last pixel */
    size_t i = (size_t)y * d->width + x;
    float *s = d->samples + d->offset[i + 1] * OBS_DEEP_CH;
    sample(s, z, a);
    s[OBS_DEEP_R] = s[OBS_DEEP_G] = s[OBS_DEEP_B] = 0.5f * a;
    d->offset[i + 1]++;
}

static void synth_next(obs_deep_image *d, int x, int y)
{
    size_t i = (size_t)y * d->width + x;
    d->offset[i + 1] = d->offset[i];
}

/* A wall at depth 10 everywhere; right of column 16 something near the
 * camera (depth 3, far in front of the wall) and, hidden behind it, a box
 * face at depth `hidden` with alpha `ha` (0: none). */
static void scene(obs_deep_image *d, float hidden, float ha)
{
    synth_init(d, 32, 32);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            synth_next(d, x, y);
            if (x >= 16) {
                synth_add(d, x, y, 3.0f, 1.0f);
                if (ha > 0.0f)
                    synth_add(d, x, y, hidden, ha);
            }
            synth_add(d, x, y, 10.0f, 1.0f);
        }
}

static obs_params deep_params(int mode)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(&p, "fov_y", "40", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "radius", "1", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "deep_mode", mode == OBS_DEEP_SINGLE ? "single" : "multi", err),
                     OBS_OK);
    return p;
}

static float ao_at(const obs_deep_image *d, const obs_params *p, int x, int y, float *blend)
{
    obs_deep_result r;
    char err[OBS_ERR_LEN] = "";
    if (obs_deep_run_cpu(d, p, &r, err) != OBS_OK)
        fail_msg("%s", err);
    float v = r.ao_front.data[y * d->width + x];
    if (blend)
        *blend = r.ao_blend.data[y * d->width + x];
    obs_deep_result_free(&r);
    return v;
}

/* The wall pixel beside the near object: its tangent sphere (radius 0.5,
 * depths 9..10) reaches the box face at 9.3, hidden behind the near
 * object.  Single-layer sees only the near object, 6.5 in front of the
 * pipes (the range check's falloff leaves almost nothing); multi-layer
 * finds the box in the second node. */
static void test_hidden_occluder(void **state)
{
    (void)state;
    obs_deep_image d;
    scene(&d, 9.3f, 1.0f);
    obs_params single = deep_params(OBS_DEEP_SINGLE), multi = deep_params(OBS_DEEP_MULTI);
    float s = ao_at(&d, &single, 15, 16, NULL);
    float m = ao_at(&d, &multi, 15, 16, NULL);
    print_message("hidden occluder: AO single %.4f, multi %.4f\n", s, m);
    assert_true(s > 0.97f);
    assert_true(m < s - 0.1f);
    /* far from the edge both agree on an open wall */
    assert_float_equal(ao_at(&d, &single, 4, 16, NULL), 1.0f, 1e-4);
    assert_float_equal(ao_at(&d, &multi, 4, 16, NULL), 1.0f, 1e-4);
    obs_deep_free(&d);

    /* without the hidden box, multi-layer equals single-layer there */
    scene(&d, 0.0f, 0.0f);
    assert_float_equal(ao_at(&d, &multi, 15, 16, NULL), s, 1e-5);
    obs_deep_free(&d);

    /* eq 1: a half-transparent box occludes (about) half as much */
    scene(&d, 9.3f, 0.5f);
    float half = ao_at(&d, &multi, 15, 16, NULL);
    print_message("alpha 0.5 box: AO %.4f\n", half);
    assert_float_equal(1.0f - half, 0.5f * (1.0f - m), 0.02f);
    obs_deep_free(&d);
}

/* ---- intervals from facing flags (deep_intervals) ---------------------------- */

static void synth_face(obs_deep_image *d, int x, int y, float z, float facing)
{
    synth_add(d, x, y, z, 1.0f);
    size_t i = (size_t)y * d->width + x;
    d->samples[(d->offset[i + 1] - 1) * OBS_DEEP_CH + OBS_DEEP_FACING] = facing;
}

/* A wall at depth 10 seen from its front (a room's wall: no back face)
 * and, right of column 16, a closed slab from depth zf (front face) to zb
 * (back face), opaque. */
static void slab_scene(obs_deep_image *d, float zf, float zb)
{
    synth_init(d, 32, 32);
    d->has_facing = 1;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            synth_next(d, x, y);
            if (x >= 16) {
                synth_face(d, x, y, zf, 1.0f);
                synth_face(d, x, y, zb, -1.0f);
            }
            synth_face(d, x, y, 10.0f, 1.0f);
        }
}

/* the wall at depth 10 (its list's last node) and over columns x0 .. x1 -
 * 1 the n faces at depths z with facing f in front of it */
static void faces_scene(obs_deep_image *d, int x0, int x1, int n, const float *z, const float *f)
{
    synth_init(d, 32, 32);
    d->has_facing = 1;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            synth_next(d, x, y);
            for (int k = 0; x >= x0 && x < x1 && k < n; k++)
                synth_face(d, x, y, z[k], f[k]);
            synth_face(d, x, y, 10.0f, 1.0f);
        }
}

/* slab_scene with the slab over columns x0 .. x1 - 1 only (a strip) */
static void strip_scene(obs_deep_image *d, float zf, float zb, int x0, int x1)
{
    const float z[2] = {zf, zb}, f[2] = {1.0f, -1.0f};
    faces_scene(d, x0, x1, 2, z, f);
}

static void slab_scene_free_and(obs_deep_image *d, float zf, float zb)
{
    obs_deep_free(d);
    slab_scene(d, zf, zb);
}

/* obs__deep_intervals on lists: a closed slab before a one-sided wall; a
 * box inside a box (nested); an open front face (a pane, no back face)
 * before a closed slab, which then stands on its own; a back face seen
 * first (from behind) and unknown facing: solid behind, as without.
 * Then (sheets 1) obs__deep_sheets, method gtao's: an unmatched node with
 * a node behind it becomes an interval of no thickness (a back face seen
 * first, a front face whose back face the list lacks); the list's last
 * node, unknown facing and matched intervals keep their ends. */
static void test_interval_lists(void **state)
{
    (void)state;
    static const struct {
        int n, sheets;
        float z[6], f[6], want[6];
    } c[] = {
        {3, 0, {2, 3, 10}, {1, -1, 1}, {3, -1, 0}},
        {5, 0, {2, 3, 4, 5, 10}, {1, 1, -1, -1, 1}, {5, -1, -1, -1, 0}},
        {4, 0, {1, 2, 3, 10}, {1, 1, -1, 1}, {0, 3, -1, 0}},
        {4, 0, {1, 2, 3, 4}, {-1, 0, 1, -1}, {0, 0, 4, -1}},
        {2, 0, {1, 0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0, 0}},
        {2, 1, {1, 10}, {-1, 1}, {1, 0}},
        {4, 1, {1, 2, 3, 10}, {1, 1, -1, 1}, {1, 3, -1, 0}},
        {3, 1, {2, 3, 10}, {1, -1, 1}, {3, -1, 0}},
        {4, 1, {1, 2, 3, 4}, {-1, 0, 1, -1}, {1, 0, 4, -1}},
        {1, 1, {1}, {-1}, {0}},
    };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        float e[6];
        obs__deep_intervals(c[i].z, c[i].f, c[i].n, e);
        if (c[i].sheets)
            obs__deep_sheets(c[i].z, c[i].f, c[i].n, e);
        for (int k = 0; k < c[i].n; k++)
            if (e[k] != c[i].want[k])
                fail_msg("list %zu node %d: end %g, want %g", i, k, e[k], c[i].want[k]);
    }
}

/* a one-sided surface at depth z (facing -1: seen from behind) over
 * columns x0 .. x1 - 1 before the wall, no back face */
static void sheet_scene(obs_deep_image *d, float z, float facing, int x0, int x1)
{
    faces_scene(d, x0, x1, 1, &z, &facing);
}

static void face_sample(float *s, float z, float facing, float tag)
{
    sample(s, z, 1.0f);
    s[OBS_DEEP_FACING] = facing;
    s[OBS_DEEP_R] = tag; /* which sample a kept node came from */
}

/* Eq 5 with intervals never splits one.  A plate (front face 1, back face
 * 1.1), a box (3 .. 3.5) and a wall seen from its front (6, no back face),
 * opaque, m = 3: eq 5 drops the farthest node; without intervals the box's
 * back face goes and its front face stays with nothing behind it closed,
 * solid to infinity ([1, 1.1, 3]); with intervals the box goes whole
 * ([1, 1.1, 6]: the plate and the wall, as obs__deep_intervals reads
 * them).  Lists without facing flags: the same as without intervals.
 * Random lists (nested and disjoint boxes, one-sided faces, random alpha
 * and insertion order): every kept node that has a partner in the whole
 * list keeps it. */
static void test_compress_intervals(void **state)
{
    (void)state;
    float in[32 * OBS_DEEP_CH], out[OBS_DEEP_MAX_LAYERS * OBS_DEEP_CH], ref[OBS_DEEP_MAX_LAYERS * OBS_DEEP_CH];
    const float z[5] = {1, 1.1f, 3, 3.5f, 6}, f[5] = {1, -1, 1, -1, 1};
    for (int k = 0; k < 5; k++)
        face_sample(in + k * OBS_DEEP_CH, z[k], f[k], (float)k);
    const float without[3] = {1, 1.1f, 3}, with[3] = {1, 1.1f, 6};
    assert_int_equal(obs__deep_compress_list(in, 5, 3, 0, 0, 0.1f, 1000.0f, out), 3);
    for (int k = 0; k < 3; k++)
        assert_float_equal(out[k * OBS_DEEP_CH + OBS_DEEP_Z], without[k], 0);
    assert_int_equal(obs__deep_compress_list(in, 5, 3, 0, 1, 0.1f, 1000.0f, out), 3);
    for (int k = 0; k < 3; k++)
        assert_float_equal(out[k * OBS_DEEP_CH + OBS_DEEP_Z], with[k], 0);
    float zk[3], fk[3], e[3];
    for (int k = 0; k < 3; k++) {
        zk[k] = out[k * OBS_DEEP_CH + OBS_DEEP_Z];
        fk[k] = out[k * OBS_DEEP_CH + OBS_DEEP_FACING];
    }
    obs__deep_intervals(zk, fk, 3, e);
    assert_float_equal(e[0], 1.1f, 0); /* the plate closed */
    assert_float_equal(e[2], 0.0f, 0); /* the wall solid behind */
    /* no facing flags: bit for bit the list without intervals */
    for (int k = 0; k < 5; k++)
        in[k * OBS_DEEP_CH + OBS_DEEP_FACING] = 0.0f;
    assert_int_equal(obs__deep_compress_list(in, 5, 3, 0, 1, 0.1f, 1000.0f, out), 3);
    assert_int_equal(obs_deep_compress_list(in, 5, 3, 0, 0.1f, 1000.0f, ref), 3);
    assert_memory_equal(out, ref, 3 * OBS_DEEP_CH * sizeof(float));

    unsigned rng = 12345u;
#define RND() ((rng = rng * 1103515245u + 12345u) >> 16 & 0x7fff)
    for (int trial = 0; trial < 500; trial++) {
        int n = 0, partner[32];
        float depth = 1.0f;
        while (n < 24) { /* a box, a box in a box, or a one-sided face */
            int kind = RND() % 4;
            if (kind == 0) {
                face_sample(in + n * OBS_DEEP_CH, depth, RND() % 2 ? 1.0f : -1.0f, (float)n);
                partner[n++] = -1;
            } else if (kind == 1 && n + 4 <= 32) {
                face_sample(in + n * OBS_DEEP_CH, depth, 1, (float)n);
                face_sample(in + (n + 1) * OBS_DEEP_CH, depth + 0.1f, 1, (float)(n + 1));
                face_sample(in + (n + 2) * OBS_DEEP_CH, depth + 0.2f, -1, (float)(n + 2));
                face_sample(in + (n + 3) * OBS_DEEP_CH, depth + 0.3f, -1, (float)(n + 3));
                partner[n] = n + 3, partner[n + 3] = n, partner[n + 1] = n + 2, partner[n + 2] = n + 1;
                n += 4;
            } else {
                face_sample(in + n * OBS_DEEP_CH, depth, 1, (float)n);
                face_sample(in + (n + 1) * OBS_DEEP_CH, depth + 0.2f, -1, (float)(n + 1));
                partner[n] = n + 1, partner[n + 1] = n;
                n += 2;
            }
            depth += 0.5f + (float)(RND() % 100) / 50.0f;
        }
        for (int k = 0; k < n; k++)
            in[k * OBS_DEEP_CH + OBS_DEEP_A] = (float)(1 + RND() % 100) / 100.0f;
        for (int k = n - 1; k > 0; k--) { /* shuffle the insertion order */
            int j = (int)(RND() % (unsigned)(k + 1));
            float t[OBS_DEEP_CH];
            memcpy(t, in + k * OBS_DEEP_CH, sizeof t);
            memcpy(in + k * OBS_DEEP_CH, in + j * OBS_DEEP_CH, sizeof t);
            memcpy(in + j * OBS_DEEP_CH, t, sizeof t);
        }
        int m = 1 + (int)(RND() % 8), c = obs__deep_compress_list(in, n, m, (int)(RND() % 2), 1,
                                                                   0.1f, 100.0f, out);
        assert_true(c >= 0 && c <= m);
        for (int k = 0; k < c; k++) {
            int tag = (int)out[k * OBS_DEEP_CH + OBS_DEEP_R], found = partner[tag] < 0;
            for (int j = 0; j < c && !found; j++)
                found = (int)out[j * OBS_DEEP_CH + OBS_DEEP_R] == partner[tag];
            if (!found)
                fail_msg("trial %d, m %d: node %d (z %g) kept without its partner", trial, m,
                         tag, out[k * OBS_DEEP_CH + OBS_DEEP_Z]);
        }
    }
#undef RND
}

/* The wall pixel beside the slab: its tangent sphere (R = 1 at depth 10
 * in this frame: the pipes span depths 8 .. 10).  A thin plate 7.5 .. 7.6
 * lies wholly in front of it:
 * with intervals nothing of the pipes is solid and the wall stays as open
 * as far from the plate (no halo); every node solid behind it (intervals
 * off, or deep_mode single, the flat buffer's view) lets the range check
 * count the plate far behind itself, the halo.  A plate 8.6 .. 8.7 that
 * reaches into the sphere occludes its own thickness only: between the
 * two.  A closed box 8.6 .. 10, flush with the wall, is solid over the
 * whole depth the flat buffer assumes: the same AO with intervals,
 * without, and on the flat chain. */
static void test_intervals(void **state)
{
    (void)state;
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    obs_params on = deep_params(OBS_DEEP_MULTI), off = deep_params(OBS_DEEP_MULTI);
    obs_params single = deep_params(OBS_DEEP_SINGLE);
    assert_int_equal(obs_param_set(&on, "deep_intervals", "on", err), OBS_OK);
    assert_int_equal(obs_param_set(&off, "deep_intervals", "off", err), OBS_OK);
    for (int i = 0; i < 3; i++) /* the AO itself, not the low-pass filter's spread */
        assert_int_equal(obs_param_set(i == 0 ? &on : i == 1 ? &off : &single, "blur", "off", err),
                         OBS_OK);

    slab_scene(&d, 7.5f, 7.6f);
    float open = ao_at(&d, &on, 4, 16, NULL);
    float with = ao_at(&d, &on, 15, 16, NULL), without = ao_at(&d, &off, 15, 16, NULL);
    float flat = ao_at(&d, &single, 15, 16, NULL);
    print_message("thin plate in front: AO open %.4f, intervals %.4f, off %.4f, single %.4f\n",
                  open, with, without, flat);
    assert_float_equal(open, 1.0f, 1e-4);
    assert_float_equal(with, open, 1e-4);
    assert_true(without < open - 0.02f);
    assert_true(flat < open - 0.02f);
    /* intervals off: the plate's back face, inside its interval, is no
     * occluder (df->inside): the front face alone, solid behind it, as a
     * flat depth buffer has it */
    assert_float_equal(without, flat, 1e-6);
    /* the same image without facing flags: every node solid behind, the
     * back face too, 0.1 nearer the wall than the front face: eq 4 thins
     * it less, a darker halo */
    d.has_facing = 0;
    float unknown = ao_at(&d, &on, 15, 16, NULL);
    print_message("thin plate in front, facing unknown: AO %.4f\n", unknown);
    assert_float_equal(ao_at(&d, &off, 15, 16, NULL), unknown, 1e-6);
    assert_true(unknown < without - 1e-3);
    /* method hemisphere alike: the back face adds nothing */
    d.has_facing = 1;
    {
        obs_params mo = off, ms = single;
        assert_int_equal(obs_param_set(&mo, "method", "hemisphere", err), OBS_OK);
        assert_int_equal(obs_param_set(&ms, "method", "hemisphere", err), OBS_OK);
        float a = ao_at(&d, &mo, 15, 16, NULL), b = ao_at(&d, &ms, 15, 16, NULL);
        d.has_facing = 0;
        float u = ao_at(&d, &mo, 15, 16, NULL);
        print_message("thin plate in front, hemisphere: AO off %.4f, single %.4f, facing "
                      "unknown %.4f\n",
                      a, b, u);
        assert_float_equal(a, b, 1e-6);
        assert_true(u < a - 1e-3);
    }
    obs_deep_free(&d);

    slab_scene(&d, 8.6f, 8.7f);
    float thin_on = ao_at(&d, &on, 15, 16, NULL), thin_off = ao_at(&d, &off, 15, 16, NULL);
    print_message("plate reaching the sphere: AO intervals %.4f, off %.4f\n", thin_on, thin_off);
    assert_true(thin_on < 1.0f - 1e-3);
    assert_true(thin_on > thin_off + 0.02f);
    obs_deep_free(&d);

    /* the closed box: every pixel as without intervals and as deep_mode
     * single (the front nodes alone, a flat depth buffer) */
    slab_scene(&d, 8.6f, 10.0f);
    obs_deep_result a, b, c;
    assert_int_equal(obs_deep_run_cpu(&d, &on, &a, err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &single, &b, err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &off, &c, err), OBS_OK);
    double worst = 0.0, lowest = 1.0;
    for (int i = 0; i < 32 * 32; i++) {
        worst = fmax(worst, fabs(a.ao_front.data[i] - b.ao_front.data[i]));
        worst = fmax(worst, fabs(a.ao_front.data[i] - c.ao_front.data[i]));
        lowest = fmin(lowest, a.ao_front.data[i]);
    }
    print_message("closed box: max |intervals - single, off| %.2e (lowest AO %.3f)\n", worst,
                  lowest);
    assert_true(worst < 1e-5);
    assert_true(lowest < 0.8); /* the crease is there */
    obs_deep_result_free(&a);
    obs_deep_result_free(&b);
    obs_deep_result_free(&c);
    obs_deep_free(&d);
}

/* Methods gtao and hbao on deep input: their horizon search reads every
 * node at a step's pixel (OITAO's multi-layer HBAO, Fig. 9).  In scene() the wall
 * pixel beside the near object (depth 3, 7 in front of the wall: beyond
 * the falloff) finds its horizon raised by the box face at 9.3 hidden
 * behind that object only in multi mode; single mode (the front nodes
 * alone) is the flat method on the front depth, pixel for pixel, and
 * without the hidden box multi equals single. */
static void horizon_deep(const char *method)
{
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    obs_params multi = deep_params(OBS_DEEP_MULTI), single = deep_params(OBS_DEEP_SINGLE);
    for (int i = 0; i < 2; i++) {
        obs_params *p = i ? &single : &multi;
        assert_int_equal(obs_param_set(p, "method", method, err), OBS_OK);
        assert_int_equal(obs_param_set(p, "blur", "off", err), OBS_OK);
    }
    scene(&d, 9.3f, 1.0f);
    float s = ao_at(&d, &single, 15, 16, NULL), m = ao_at(&d, &multi, 15, 16, NULL);
    print_message("%s, hidden occluder: AO single %.4f, multi %.4f\n", method, s, m);
    assert_true(m < s - 0.05f);
    assert_float_equal(ao_at(&d, &multi, 4, 16, NULL), ao_at(&d, &single, 4, 16, NULL), 1e-6);

    /* single = the flat chain's method (CPU) on the front nodes' depth */
    obs_deep_result a;
    assert_int_equal(obs_deep_run_cpu(&d, &single, &a, err), OBS_OK);
    float depth[32 * 32];
    for (int i = 0; i < 32 * 32; i++)
        depth[i] = d.samples[d.offset[i] * OBS_DEEP_CH + OBS_DEEP_Z];
    obs_gbuffer gb = {0};
    gb.width = gb.height = 32;
    gb.depth = (obs_plane){depth, 1, 0};
    obs_result fr;
    assert_int_equal(obs_run_cpu(&gb, &single, OBS_OUTPUT_AO, &fr, err), OBS_OK);
    double worst = 0.0;
    for (int i = 0; i < 32 * 32; i++)
        worst = fmax(worst, fabs(a.ao_front.data[i] - fr.ao.data[i]));
    print_message("%s, single vs the flat chain: max |diff| %.2e\n", method, worst);
    assert_true(worst < 1e-4);
    obs_deep_result_free(&a);
    obs_result_free(&fr);
    obs_deep_free(&d);

    scene(&d, 0.0f, 0.0f);
    assert_float_equal(ao_at(&d, &multi, 15, 16, NULL), ao_at(&d, &single, 15, 16, NULL), 1e-6);
    obs_deep_free(&d);
}

static void test_gtao_deep(void **state)
{
    (void)state;
    horizon_deep("gtao");
}

static void test_hbao_deep(void **state)
{
    (void)state;
    horizon_deep("hbao");
}

/* Method gtao with intervals (methods/gtao_deep.c): each slice's
 * visibility over its free arcs.  The wall pixel beside a thin plate
 * (0.1 thick, two pixels wide) 0.7 in front of the wall (well within
 * gtao's search radius, 1.457 R): every node solid behind it (intervals
 * off, deep_mode single: the flat buffer's view) puts the plate's horizon
 * over everything under it, the halo; with the plate's back face known
 * the rays passing behind it to the wall are free, and the plate occupies
 * only the angles where it is (a plate as wide as the image blocks most
 * rays rising from the wall beside it: that is occlusion, not a halo).  Lists of
 * one front face each (a height field: every node solid behind) give
 * the horizon form to the bit, and a closed box flush with
 * the wall (its back face on the wall) the flat buffer's AO. */
static obs_params gtao_params(int mode, const char *intervals)
{
    char err[OBS_ERR_LEN] = "";
    obs_params p = deep_params(mode);
    assert_int_equal(obs_param_set(&p, "method", "gtao", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "blur", "off", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "deep_intervals", intervals, err), OBS_OK);
    return p;
}

/* p with the rows gtao on deep input takes with intervals
 * (OBS_DEEP_GTAO_EXACT) given explicitly */
static obs_params gtao_exact(obs_params p)
{
    char err[OBS_ERR_LEN] = "";
#define SET_ROW(name, value) assert_int_equal(obs_param_set(&p, #name, value, err), OBS_OK);
    OBS_DEEP_GTAO_EXACT(SET_ROW)
#undef SET_ROW
    return p;
}

/* the largest |a - b| over the front AO of every pixel */
static double ao_diff(const obs_deep_image *d, const obs_params *a, const obs_params *b)
{
    obs_deep_result ra, rb;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_deep_run_cpu(d, a, &ra, err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(d, b, &rb, err), OBS_OK);
    double worst = 0.0;
    for (int i = 0; i < d->width * d->height; i++)
        worst = fmax(worst, fabs(ra.ao_front.data[i] - rb.ao_front.data[i]));
    obs_deep_result_free(&ra);
    obs_deep_result_free(&rb);
    return worst;
}

static void test_gtao_intervals(void **state)
{
    (void)state;
    obs_deep_image d;
    obs_params on = gtao_params(OBS_DEEP_MULTI, "on"), off = gtao_params(OBS_DEEP_MULTI, "off");
    obs_params single = gtao_params(OBS_DEEP_SINGLE, "off");

    strip_scene(&d, 9.3f, 9.4f, 16, 18);
    float open = ao_at(&d, &on, 4, 16, NULL);
    float with = ao_at(&d, &on, 15, 16, NULL), without = ao_at(&d, &off, 15, 16, NULL);
    float flat = ao_at(&d, &single, 15, 16, NULL);
    print_message("gtao, thin plate in front: AO open %.4f, intervals %.4f, off %.4f, single %.4f\n",
                  open, with, without, flat);
    assert_true(without < open - 0.05f); /* the halo */
    assert_true(flat < open - 0.05f);
    assert_true(with <= open + 1e-6f); /* the plate's thickness still occupies its arc */
    assert_true(open - with < 0.5f * (open - without));
    obs_deep_free(&d);

    /* front faces only, one a list (a height field: each its list's last
     * node, solid behind it): the horizon form.  With a node behind a
     * one-sided surface the surface is a sheet (test_gtao_sheet). */
    synth_init(&d, 32, 32);
    d.has_facing = 1;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            synth_next(&d, x, y);
            synth_face(&d, x, y, x >= 16 ? 9.3f : 10.0f, 1.0f);
        }
    /* with intervals gtao takes the exact rows where unset; off, single
     * keep XeGTAO's defaults: compared with the same parameters */
    obs_params off_x = gtao_exact(off), single_x = gtao_exact(single);
    double same = ao_diff(&d, &on, &off_x);
    print_message("gtao, one-sided surfaces: max |intervals - off| %.2e\n", same);
    assert_true(same == 0.0);
    obs_deep_free(&d);

    /* the closed box flush with the wall (0.7 deep, D = 1): as the flat
     * buffer with the same parameters (single: the flat chain to the bit,
     * test_gtao_deep) on the box and in the crease beside it (x >= 15);
     * further off the flat buffer drops a box column whose front lies
     * beyond D though the box's side still reaches into D (a ray that
     * left the previous column within D meets it): there the intervals
     * are darker, never lighter */
    slab_scene(&d, 9.3f, 10.0f);
    double box = 0.0, far = 0.0;
    {
        obs_deep_result ra, rb;
        char e2[OBS_ERR_LEN] = "";
        assert_int_equal(obs_deep_run_cpu(&d, &on, &ra, e2), OBS_OK);
        assert_int_equal(obs_deep_run_cpu(&d, &single_x, &rb, e2), OBS_OK);
        for (int i = 0; i < d.width * d.height; i++) {
            double diff = ra.ao_front.data[i] - rb.ao_front.data[i];
            if (i % d.width >= 15)
                box = fmax(box, fabs(diff));
            else
                far = fmax(far, diff);
        }
        obs_deep_result_free(&ra);
        obs_deep_result_free(&rb);
    }
    float crease = ao_at(&d, &on, 15, 16, NULL);
    print_message("gtao, closed box: max |intervals - single| %.2e on it and within D, intervals - "
                  "single further %.2e (AO beside it %.3f)\n", box, far, crease);
    assert_true(box < 1e-5);
    assert_true(far < 1e-6);
    assert_true(ao_diff(&d, &off_x, &single_x) < 1e-5); /* off = single */
    assert_true(crease < 0.95f); /* the crease is there */

    /* the defaults with intervals are the exact rows, bit for bit; a
     * parameter given explicitly wins; auto is on for gtao */
    obs_params on_x = gtao_exact(on), on_p = on, aut = gtao_params(OBS_DEEP_MULTI, "auto");
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&on_p, "gtao_power", "2.2", err), OBS_OK);
    assert_true(ao_diff(&d, &on, &on_x) == 0.0);
    assert_true(ao_diff(&d, &on, &aut) == 0.0);
    assert_true(ao_diff(&d, &on, &on_p) > 1e-3);
    obs_deep_free(&d);

    /* a strip 1.2 in front of the wall (D = 1): no ray from the wall
     * beside it meets it within D.  With the defaults the search stops at
     * D: the wall beside it is open, AO 1 (no halo); XeGTAO's defaults
     * (without intervals) search 1.457 D with a soft falloff and darken
     * it. */
    strip_scene(&d, 8.7f, 8.8f, 16, 18);
    float far_open = ao_at(&d, &on, 4, 16, NULL), far_on = ao_at(&d, &on, 15, 16, NULL);
    float far_off = ao_at(&d, &off_x, 15, 16, NULL), far_xe = ao_at(&d, &off, 15, 16, NULL);
    print_message("gtao, strip beyond D: AO open %.4f, defaults %.4f, no intervals %.4f, XeGTAO's "
                  "defaults %.4f\n", far_open, far_on, far_off, far_xe);
    assert_true(far_on > 1.0f - 1e-5f && far_on >= far_open);
    assert_true(far_xe < far_on - 0.03f);
    obs_params r;
    obs_deep_params_resolve(&d, &on_p, &r);
    assert_float_equal(r.gtao_power, 2.2f, 0);
    assert_float_equal(r.gtao_radius_multiplier, 1.0f, 0);
    assert_int_equal(r.gtao_heuristics, OBS_OFF);
    obs_deep_params_resolve(&d, &off, &r); /* off: XeGTAO's defaults */
    assert_float_equal(r.gtao_radius_multiplier, 1.457f, 1e-6);
    obs_deep_free(&d);
}

/* The AO of the last node of pixel (x, y) (obs_deep_ao_nodes) */
static float last_node_ao(const obs_deep_image *d, const obs_params *p, int x, int y)
{
    obs_deep_ao a;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_deep_ao_nodes(d, p, &a, err), OBS_OK);
    size_t i = (size_t)y * (size_t)d->width + (size_t)x;
    assert_true(a.offset[i + 1] > a.offset[i]);
    float v = a.node[(a.offset[i + 1] - 1) * OBS_DEEP_AO_CH + OBS_DEEP_AO_AO];
    obs_deep_ao_free(&a);
    return v;
}

/* The wall under a closed slab raised off it (the ground under an
 * animal's belly): the slab's back face at height h = 0.6 over the wall,
 * D = 1, the slab covering the whole image.  With the hard cut a ray
 * from the wall at angle t from the normal meets the slab within D where
 * h / cos t <= D: the cosine-weighted open part is the rays with cos t <
 * h / D, exactly (h / D)^2 = 0.36, whatever the slab's thickness (the
 * solid beyond D does not count).  A slab whose front face lies beyond D
 * (8.8, 1.2 over the wall) must give the thin slab's AO (front within D
 * for the near columns): mapping that front face's angle to the tangent
 * (XeGTAO's falloff for a horizon point beyond the radius) occupied
 * every angle from the back face down to the tangent, the open gap under
 * the slab (AO near 0).  The slab's faces lie at one depth each, where
 * the distance at which a ray meets them is exact (gtao_deep.c,
 * add_reach). */
static void test_gtao_raised_slab(void **state)
{
    (void)state;
    obs_deep_image d;
    obs_params on = gtao_params(OBS_DEEP_MULTI, "on");
    strip_scene(&d, 9.3f, 9.4f, 0, 32);
    float thin = last_node_ao(&d, &on, 16, 16);
    obs_deep_free(&d);
    strip_scene(&d, 8.8f, 9.4f, 0, 32);
    float thick = last_node_ao(&d, &on, 16, 16);
    obs_deep_free(&d);
    const float exact = 0.6f * 0.6f;
    print_message("gtao, wall under a raised slab: AO thin %.4f, front beyond D %.4f, exact %.4f\n",
                  thin, thick, exact);
    assert_true(fabsf(thick - thin) < 1e-3f);
    assert_true(fabsf(thick - exact) < 0.01f && fabsf(thin - exact) < 0.01f);
}

/* A list cut by eq 5 behind a closed interval (deep_layers 2: the strip's
 * front and back face kept, the wall behind dropped) does not say what
 * lies behind the strip: it stays open there (OBS__DEEP_END_CUT), so the
 * wall beside the strip gets the AO it has with the whole lists (m = 4);
 * taking the strip as solid behind (the rule for a list that ends there)
 * put the halo back (before: 0.598 at m = 2 against 0.780 at m = 4). */
/* A one-sided strip (an open mesh: no back face) in front of the wall,
 * seen from behind (a lone back face) or from the front with the wall
 * behind it in the list: the wall beside it gets the AO of a closed strip
 * of no thickness at the same depth, whatever the strip's facing.  Taken
 * solid behind (the rule for a list's last node), its horizon covered
 * the whole gap between strip and wall: on the street scene such columns,
 * met more often as the steps get denser, darkened the AO away from the
 * ray tracer's (0.6 at 16 steps, 0.45 at 32 where the ray tracer has
 * 0.87 at one pixel). */
static void test_gtao_sheet(void **state)
{
    (void)state;
    obs_deep_image d;
    obs_params on = gtao_params(OBS_DEEP_MULTI, "on");
    strip_scene(&d, 9.3f, 9.3f, 16, 18);
    const float closed = ao_at(&d, &on, 15, 16, NULL), open = ao_at(&d, &on, 4, 16, NULL);
    obs_deep_free(&d);
    float sheet[2];
    /* the strip solid behind (the previous rule): every node solid
     * behind, the horizon form, as without intervals at the same rows */
    const obs_params off = gtao_exact(gtao_params(OBS_DEEP_MULTI, "off"));
    float solid = 0.0f;
    for (int i = 0; i < 2; i++) {
        sheet_scene(&d, 9.3f, i ? 1.0f : -1.0f, 16, 18);
        sheet[i] = ao_at(&d, &on, 15, 16, NULL);
        solid = ao_at(&d, &off, 15, 16, NULL);
        obs_deep_free(&d);
    }
    print_message("gtao, one-sided strip before the wall: AO beside it seen from behind %.4f, "
                  "from the front %.4f, closed strip of no thickness %.4f, open wall %.4f, "
                  "strip solid behind %.4f\n", sheet[0], sheet[1], closed, open, solid);
    assert_true(closed < open - 0.01f); /* the strip occludes the wall beside it */
    assert_true(solid < closed - 0.05f); /* a horizon over the gap behind it */
    assert_float_equal(sheet[0], closed, 1e-6);
    assert_float_equal(sheet[1], closed, 1e-6);
}

static void test_gtao_cut_list(void **state)
{
    (void)state;
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    obs_params m4 = gtao_params(OBS_DEEP_MULTI, "on"), m2 = m4;
    assert_int_equal(obs_param_set(&m2, "deep_layers", "2", err), OBS_OK);
    strip_scene(&d, 9.3f, 9.4f, 16, 18);
    float beside4 = ao_at(&d, &m4, 15, 16, NULL), beside2 = ao_at(&d, &m2, 15, 16, NULL);
    double worst = 0.0; /* over the wall (the strip's own lists lose the wall behind it) */
    obs_deep_result r4, r2;
    assert_int_equal(obs_deep_run_cpu(&d, &m4, &r4, err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &m2, &r2, err), OBS_OK);
    for (int i = 0; i < d.width * d.height; i++)
        if (i % d.width < 16 || i % d.width >= 18)
            worst = fmax(worst, fabs(r4.ao_front.data[i] - r2.ao_front.data[i]));
    obs_deep_result_free(&r4);
    obs_deep_result_free(&r2);
    print_message("gtao, list cut behind a strip: AO beside it m = 4 %.4f, m = 2 %.4f, max |diff| "
                  "over the wall %.2e\n", beside4, beside2, worst);
    /* m = 2 also drops the wall's own node at the strip's columns, whose
     * horizon (c is scaled by 0.99999 off the wall) adds a trace */
    assert_true(worst < 5e-3);
    assert_true(fabsf(beside4 - beside2) < 1e-3);
    obs_deep_free(&d);
}

/* A floor seen at a grazing angle (view plane 2y + z = -6, one opaque
 * node per pixel, normals derived from depth) with a tangent sphere
 * smaller than a pixel (radius 0.002): a sample on the shaded pixel reads
 * the receiver node's tangent plane, as the flat estimator does
 * (test_vao_math.c), so the open floor stays open; with the node's depth
 * at the pixel's centre it would occlude itself. */
static void grazing_floor(obs_deep_image *d)
{
    synth_init(d, 32, 32);
    const float t = tanf(20.0f * (float)M_PI / 180.0f); /* fov_y 40 */
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            synth_next(d, x, y);
            float dy = (1.0f - (y + 0.5f) / 16.0f) * t; /* view ray (., dy, -1) */
            synth_add(d, x, y, 6.0f / (1.0f - 2.0f * dy), 1.0f);
        }
}

static obs_params subpixel_params(int volume)
{
    obs_params p = deep_params(OBS_DEEP_MULTI);
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(&p, "radius", "0.002", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "ao_definition", volume ? "volume" : "rays", err), OBS_OK);
    return p;
}

static void test_subpixel_sphere(void **state)
{
    (void)state;
    obs_deep_image d;
    grazing_floor(&d);
    for (int v = 0; v < 2; v++) {
        obs_params p = subpixel_params(v);
        char err[OBS_ERR_LEN];
        obs_deep_result r;
        if (obs_deep_run_cpu(&d, &p, &r, err) != OBS_OK)
            fail_msg("%s", err);
        float mn = 1.0f;
        for (int y = 1; y < 31; y++)
            for (int x = 1; x < 31; x++)
                mn = fminf(mn, r.ao_front.data[y * 32 + x]);
        print_message("deep grazing floor, sphere under a pixel, %s: min AO %.6f\n",
                      v ? "volume" : "rays", mn);
        assert_true(mn > 0.999f);
        obs_deep_result_free(&r);
    }
    obs_deep_free(&d);
}

/* A valley whose crease runs down the middle of the image, from the top
 * border to the bottom one: two walls at 45 degrees meeting at planar
 * depth 6, their camera-space normals given (a crease pixel's is its own
 * wall's, not one reconstructed across the crease). */
static void valley_scene(obs_deep_image *d)
{
    synth_init(d, 64, 64);
    const float t = tanf(20.0f * (float)M_PI / 180.0f); /* fov_y 40, square */
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            synth_next(d, x, y);
            float dx = (2.0f * (x + 0.5f) / 64.0f - 1.0f) * t; /* view ray (dx, ., -1) */
            synth_add(d, x, y, 6.0f / (1.0f + fabsf(dx)), 1.0f);
            float *n = d->samples + (d->offset[y * 64 + x + 1] - 1) * OBS_DEEP_CH;
            n[OBS_DEEP_NX] = (dx < 0.0f ? 1.0f : -1.0f) * sqrtf(0.5f);
            n[OBS_DEEP_NY] = 0.0f;
            n[OBS_DEEP_NZ] = sqrtf(0.5f);
        }
    d->has_normal = 1;
}

/* One layer of deep input is a flat G-buffer: deep_mode single on the
 * valley gives the flat chain's AO on the same depth and normals, at the
 * border too, where the spheres' line samples fall off the image and
 * both read the surface continued past it (border_cpu.c).  (Left out of
 * eq 1 there, as the deep chain's were, the AO within 8 pixels of the
 * border differed from the flat chain's by up to 0.17, and by 0.008
 * farther in, where the spheres still reach past it.)  The flat chain runs without
 * adaptive sampling and culling, which the deep chain does not have. */
static void test_single_is_flat(void **state)
{
    (void)state;
    obs_deep_image d;
    valley_scene(&d);
    const size_t npx = 64 * 64;
    float *depth = malloc(npx * sizeof *depth), *nrm = malloc(npx * 3 * sizeof *nrm);
    for (size_t i = 0; i < npx; i++) {
        const float *sp = d.samples + d.offset[i] * OBS_DEEP_CH;
        depth[i] = sp[OBS_DEEP_Z];
        for (int c = 0; c < 3; c++)
            nrm[3 * i + c] = sp[OBS_DEEP_NX + c];
    }
    obs_gbuffer gb = {0};
    gb.width = gb.display_width = 64;
    gb.height = gb.display_height = 64;
    gb.depth = (obs_plane){depth, 1, 0};
    gb.normal = (obs_plane){nrm, 3, 0};
    const char *const defs[] = {"volume", "rays"};
    for (int v = 0; v < 2; v++) {
        obs_params p = deep_params(OBS_DEEP_SINGLE);
        char err[OBS_ERR_LEN];
        assert_int_equal(obs_param_set(&p, "blur", "off", err), OBS_OK);
        assert_int_equal(obs_param_set(&p, "normal_space", "camera", err), OBS_OK);
        assert_int_equal(obs_param_set(&p, "ao_definition", defs[v], err), OBS_OK);
        assert_int_equal(obs_param_set(&p, "adaptive", "off", err), OBS_OK);
        assert_int_equal(obs_param_set(&p, "culling", "off", err), OBS_OK);
        obs_deep_result r;
        obs_result f;
        if (obs_deep_run_cpu(&d, &p, &r, err) != OBS_OK)
            fail_msg("%s", err);
        assert_int_equal(obs_run_cpu(&gb, &p, OBS_OUTPUT_AO, &f, err), OBS_OK);
        double border = 0.0, inside = 0.0;
        for (size_t i = 0; i < npx; i++) {
            double e = fabs(r.ao_front.data[i] - f.ao.data[i]);
            if (i < 8 * 64 || i >= 56 * 64 || i % 64 < 8 || i % 64 >= 56)
                border = fmax(border, e);
            else
                inside = fmax(inside, e);
        }
        print_message("valley, %s: deep single against the flat chain, max |diff| within 8 "
                      "pixels of the border %.2e, inside %.2e\n",
                      defs[v], border, inside);
        assert_true(inside < 1e-4);
        assert_true(border < 1e-4);
        obs_deep_result_free(&r);
        obs_result_free(&f);
    }
    free(depth);
    free(nrm);
    obs_deep_free(&d);
}

/* Method hemisphere on deep input: the same hidden box occludes the wall
 * pixel beside the near object in multi-layer mode and not in single
 * mode; the near object, 7 in front of the receiver, fades out by the
 * method's range check in both. */
static void test_hidden_occluder_hemisphere(void **state)
{
    (void)state;
    obs_deep_image d;
    char err[OBS_ERR_LEN];
    obs_params single = deep_params(OBS_DEEP_SINGLE), multi = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&single, "method", "hemisphere", err), OBS_OK);
    assert_int_equal(obs_param_set(&multi, "method", "hemisphere", err), OBS_OK);
    scene(&d, 9.3f, 1.0f);
    float s = ao_at(&d, &single, 15, 16, NULL);
    float m = ao_at(&d, &multi, 15, 16, NULL);
    print_message("hemisphere, hidden occluder: AO single %.4f, multi %.4f\n", s, m);
    assert_true(s > 0.95f);
    assert_true(m < s - 0.1f);
    assert_float_equal(ao_at(&d, &single, 4, 16, NULL), 1.0f, 1e-5);
    assert_float_equal(ao_at(&d, &multi, 4, 16, NULL), 1.0f, 1e-5);
    obs_deep_free(&d);

    /* without the hidden box, multi-layer equals single-layer there */
    scene(&d, 0.0f, 0.0f);
    assert_float_equal(ao_at(&d, &multi, 15, 16, NULL), s, 1e-6);

    /* one opaque node per pixel, single mode: the flat hemisphere kernel
     * (obs__hemisphere_pixel) with the front node plane as depth buffer */
    obs__deep_frame df;
    if (obs__deep_frame_setup(&d, &single, &df, err) != OBS_OK)
        fail_msg("%s", err);
    for (int y = 0; y < d.height; y += 3)
        for (int x = 0; x < d.width; x += 3) {
            size_t i = (size_t)y * d.width + x;
            const float *pp = df.pos + 4 * i, *nn = df.nrm + 4 * i;
            float flat = obs__hemisphere_pixel(&df.f, df.pos, x, y, pp, nn);
            assert_float_equal(obs__deep_node_ao(&df, x, y, 0), flat, 1e-6);
        }
    obs__deep_frame_free(&df);
    obs_deep_free(&d);

    /* eq 1: a half-transparent box occludes (about) half as much */
    scene(&d, 9.3f, 0.5f);
    float half = ao_at(&d, &multi, 15, 16, NULL);
    print_message("hemisphere, alpha 0.5 box: AO %.4f\n", half);
    assert_float_equal(1.0f - half, 0.5f * (1.0f - m), 0.02f);
    obs_deep_free(&d);
}

/* Deep input takes methods vaopp, vao and hemisphere; the others are
 * refused with a message naming the method. */
static void test_methods_refused(void **state)
{
    (void)state;
    static const char *const refused[] = {"angle"};
    obs_deep_image d;
    obs_deep_result r;
    scene(&d, 9.3f, 1.0f);
    for (int k = 0; k < 1; k++) {
        obs_params p = deep_params(OBS_DEEP_MULTI);
        char err[OBS_ERR_LEN] = "", want[64];
        assert_int_equal(obs_param_set(&p, "method", refused[k], err), OBS_OK);
        assert_int_equal(obs_deep_run_cpu(&d, &p, &r, err), OBS_INVALID_ARGUMENT);
        snprintf(want, sizeof want, "method %s does not run on deep input", refused[k]);
        if (!strstr(err, want))
            fail_msg("unexpected message: %s", err);
        assert_null(r.ao_blend.data);
    }
    obs_deep_free(&d);
}

/* The blend of OITAO III's separated scheme and eq 1's receiver alpha: a
 * pane of alpha a over a wall gives a AO_pane + (1 - a) AO_wall; with
 * thin hulls the front face weighs exterior AO by alpha (eqs 2-4). */
static void test_blend_and_hull(void **state)
{
    (void)state;
    obs_deep_image d;
    obs_params p = deep_params(OBS_DEEP_MULTI);
    char err[OBS_ERR_LEN];
    float blend;
    /* a pane of alpha 0.4 at 9.8 over the wall at 10, everywhere */
    synth_init(&d, 24, 24);
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 24; x++) {
            synth_next(&d, x, y);
            synth_add(&d, x, y, 9.8f, 0.4f);
            synth_add(&d, x, y, 10.0f, 1.0f);
        }
    obs_deep_result r;
    assert_int_equal(obs_deep_run_cpu(&d, &p, &r, err), OBS_OK);
    size_t c = 12 * 24 + 12;
    /* the pane is open (nothing in its sphere): AO 1 */
    assert_float_equal(r.ao_front.data[c], 1.0f, 1e-5);
    /* the wall, 0.2 behind the pane, sees it in its sphere; eq 1 weights the
     * pane's occlusion by its 0.4 */
    blend = r.ao_blend.data[c];
    assert_true(blend < 1.0f && blend > 0.6f);
    /* composite: over of (0.2, 0.2, 0.2, 0.4) and (0.5, 0.5, 0.5, 1) */
    float want = (0.2f + 0.6f * 0.5f) * blend;
    assert_float_equal(r.composite.data[4 * c], want, 1e-5);
    assert_float_equal(r.composite.data[4 * c + 3], 1.0f, 1e-6);
    obs_deep_result_free(&r);
    assert_int_equal(obs_param_set(&p, "deep_hull", "thin", err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &r, err), OBS_OK);
    /* the pane's interior sphere (behind it) holds the wall: W = 0.4 of
     * the open exterior, 0.6 of the occluded interior */
    assert_true(r.ao_front.data[c] < 0.9f);
    obs_deep_result_free(&r);

    /* the same with method hemisphere: the pane is open as a solid
     * volume; as a thin hull its interior hemisphere reaches the wall 0.2
     * behind it (the pane itself, on the exterior side, hides nothing) */
    p = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&p, "method", "hemisphere", err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &r, err), OBS_OK);
    assert_float_equal(r.ao_front.data[c], 1.0f, 1e-5);
    blend = r.ao_blend.data[c];
    print_message("hemisphere, pane over wall: blended AO %.4f\n", blend);
    assert_true(blend < 1.0f && blend > 0.6f);
    obs_deep_result_free(&r);
    assert_int_equal(obs_param_set(&p, "deep_hull", "thin", err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &r, err), OBS_OK);
    print_message("hemisphere, thin pane: front AO %.4f\n", r.ao_front.data[c]);
    assert_true(r.ao_front.data[c] < 0.9f);
    obs_deep_result_free(&r);
    obs_deep_free(&d);
}

/* ---- GL against the CPU twin ------------------------------------------------ */

static void compare_gl(obs_ctx *ctx, const obs_deep_image *d, const obs_params *p, const char *what)
{
    obs_deep_result g, c;
    char err[OBS_ERR_LEN] = "";
    if (obs_deep_run(ctx, d, p, &g, err) != OBS_OK)
        fail_msg("%s: GL: %s", what, err);
    assert_int_equal(obs_deep_run_cpu(d, p, &c, err), OBS_OK);
    size_t n = (size_t)d->width * d->height;
    double worst = 0.0, sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double e = fmax(fabs(g.ao_front.data[i] - c.ao_front.data[i]),
                        fabs(g.ao_blend.data[i] - c.ao_blend.data[i]));
        worst = fmax(worst, e);
        sum += e;
    }
    print_message("%s: GL vs CPU max |diff| %.2e, mean %.2e\n", what, worst, sum / (double)n);
    assert_true(worst < 2e-3);
    assert_true(sum / (double)n < 1e-5);
    obs_deep_result_free(&g);
    obs_deep_result_free(&c);
}

/* compare_gl for the AO of every kept node (obs_deep_run_nodes against
 * obs_deep_ao_nodes): the hidden receivers */
static void compare_gl_nodes(obs_ctx *ctx, const obs_deep_image *d, const obs_params *p,
                             const char *what)
{
    obs_deep_result g;
    obs_deep_ao gn, cn;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_deep_run_nodes(ctx, d, p, &g, &gn, err), OBS_OK);
    assert_int_equal(obs_deep_ao_nodes(d, p, &cn, err), OBS_OK);
    size_t npx = (size_t)d->width * (size_t)d->height;
    assert_true(gn.offset[npx] == cn.offset[npx]);
    double worst = 0.0;
    for (uint64_t k = 0; k < cn.offset[npx]; k++)
        worst = fmax(worst, fabs(gn.node[k * OBS_DEEP_AO_CH + OBS_DEEP_AO_AO] -
                                 cn.node[k * OBS_DEEP_AO_CH + OBS_DEEP_AO_AO]));
    print_message("%s: GL vs CPU, every node, max |diff| %.2e\n", what, worst);
    assert_true(worst < 2e-3);
    obs_deep_result_free(&g);
    obs_deep_ao_free(&gn);
    obs_deep_ao_free(&cn);
}

static void test_gl_twin(void **state)
{
    (void)state;
    obs_ctx *ctx = NULL;
    obs_ctx_desc desc = {0};
    char err[OBS_ERR_LEN] = "";
    if (obs_ctx_create(&desc, &ctx, err) != OBS_OK) {
        print_message("no GL context (%s): skipped\n", err);
        skip();
    }
    obs_deep_image d;
    scene(&d, 9.8f, 0.7f);
    obs_params p = deep_params(OBS_DEEP_MULTI);
    compare_gl(ctx, &d, &p, "hidden occluder, multi");
    p = deep_params(OBS_DEEP_SINGLE);
    compare_gl(ctx, &d, &p, "hidden occluder, single");
    /* the depth range check compiled out (the deep pass's variants) */
    p = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&p, "range_check", "off", err), OBS_OK);
    compare_gl(ctx, &d, &p, "hidden occluder, multi, range check off");
    obs_deep_free(&d);
    /* intervals from facing flags (the pass's OBS_DEEP_INTERVALS variant) */
    slab_scene(&d, 8.6f, 8.7f);
    p = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&p, "deep_intervals", "on", err), OBS_OK);
    compare_gl(ctx, &d, &p, "thin plate, intervals");
    slab_scene_free_and(&d, 7.5f, 7.6f);
    compare_gl(ctx, &d, &p, "plate in front, intervals");
    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    compare_gl(ctx, &d, &p, "plate in front, intervals, m = 2");
    /* intervals off, facing flags known: the nodes inside an interval left out */
    assert_int_equal(obs_param_set(&p, "deep_intervals", "off", err), OBS_OK);
    compare_gl(ctx, &d, &p, "plate in front, intervals off, m = 2");
    assert_int_equal(obs_param_set(&p, "method", "hemisphere", err), OBS_OK);
    compare_gl(ctx, &d, &p, "plate in front, hemisphere, m = 2");
    assert_int_equal(obs_param_set(&p, "method", "hbao", err), OBS_OK);
    compare_gl(ctx, &d, &p, "plate in front, hbao, m = 2");
    obs_deep_free(&d);
    scene(&d, 9.8f, 0.7f);
    obs_deep_free(&d);
    /* the receiver's own tangent plane (spheres under a pixel) */
    grazing_floor(&d);
    p = subpixel_params(0);
    compare_gl(ctx, &d, &p, "grazing floor, sphere under a pixel, rays");
    p = subpixel_params(1);
    compare_gl(ctx, &d, &p, "grazing floor, sphere under a pixel, volume");
    obs_deep_free(&d);
    assert_int_equal(obs_deep_read_exr(FIXTURE, NULL, &d, err), OBS_OK);
    p = (obs_params){0};
    assert_int_equal(obs_param_set(&p, "radius", "1", err), OBS_OK);
    compare_gl(ctx, &d, &p, "fixture, solid");
    assert_int_equal(obs_param_set(&p, "deep_hull", "thin", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "deep_front_half", "on", err), OBS_OK);
    compare_gl(ctx, &d, &p, "fixture, thin, m = 2, front half");
    /* method hemisphere: the program with its point samples */
    p = (obs_params){0};
    assert_int_equal(obs_param_set(&p, "radius", "1", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "method", "hemisphere", err), OBS_OK);
    compare_gl(ctx, &d, &p, "fixture, hemisphere, solid");
    assert_int_equal(obs_param_set(&p, "hemisphere_samples", "16", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "deep_hull", "thin", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    compare_gl(ctx, &d, &p, "fixture, hemisphere, thin, m = 2");
    obs_deep_free(&d);
    scene(&d, 9.8f, 0.7f);
    p = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&p, "method", "hemisphere", err), OBS_OK);
    compare_gl(ctx, &d, &p, "hidden occluder, hemisphere, multi");
    p = deep_params(OBS_DEEP_SINGLE);
    assert_int_equal(obs_param_set(&p, "method", "hemisphere", err), OBS_OK);
    compare_gl(ctx, &d, &p, "hidden occluder, hemisphere, single");
    /* method gtao: the program with gtao.glsl over the nodes */
    p = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&p, "method", "gtao", err), OBS_OK);
    compare_gl(ctx, &d, &p, "hidden occluder, gtao, multi");
    p = deep_params(OBS_DEEP_SINGLE);
    assert_int_equal(obs_param_set(&p, "method", "gtao", err), OBS_OK);
    compare_gl(ctx, &d, &p, "hidden occluder, gtao, single");
    p = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&p, "method", "hbao", err), OBS_OK);
    compare_gl(ctx, &d, &p, "hidden occluder, hbao, multi");
    obs_deep_free(&d);
    /* method gtao with intervals (gtao.glsl's GT_INTERVALS) */
    slab_scene(&d, 9.3f, 9.4f);
    p = gtao_params(OBS_DEEP_MULTI, "on");
    compare_gl(ctx, &d, &p, "thin plate, gtao, intervals");
    slab_scene_free_and(&d, 9.3f, 10.0f);
    compare_gl(ctx, &d, &p, "closed box, gtao, intervals");
    slab_scene_free_and(&d, 8.6f, 8.7f);
    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    compare_gl(ctx, &d, &p, "thin plate, gtao, intervals, m = 2");
    obs_deep_free(&d);
    /* the defaults (deep_intervals auto: intervals and the exact rows) on
     * a strip before the wall, lists longer than m = 2: the compression
     * drops whole intervals on both paths */
    strip_scene(&d, 9.3f, 9.4f, 12, 15);
    p = deep_params(OBS_DEEP_MULTI);
    assert_int_equal(obs_param_set(&p, "method", "gtao", err), OBS_OK);
    compare_gl(ctx, &d, &p, "thin strip, gtao, defaults");
    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    compare_gl(ctx, &d, &p, "thin strip, gtao, defaults, m = 2");
    obs_deep_free(&d);
    /* the wall under a slab raised off it (test_gtao_raised_slab): the
     * hidden receiver's own column, solids reached within D */
    strip_scene(&d, 8.8f, 9.4f, 0, 32);
    p = gtao_params(OBS_DEEP_MULTI, "on");
    compare_gl_nodes(ctx, &d, &p, "raised slab, gtao, defaults");
    obs_deep_free(&d);
    /* lists cut behind a strip (test_gtao_cut_list): OBS__DEEP_END_CUT */
    strip_scene(&d, 9.3f, 9.4f, 16, 18);
    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    compare_gl(ctx, &d, &p, "strip, lists cut, gtao, defaults, m = 2");
    obs_deep_free(&d);
    /* one-sided strips before the wall (test_gtao_sheet): sheets */
    p = gtao_params(OBS_DEEP_MULTI, "on");
    sheet_scene(&d, 9.3f, -1.0f, 16, 18);
    compare_gl(ctx, &d, &p, "one-sided strip seen from behind, gtao, defaults");
    obs_deep_free(&d);
    obs_ctx_destroy(ctx);
}

/* The deep pass keeps its program and targets: a second frame of the same
 * size and node count creates no GL objects and gives the same AO; another
 * node count makes one new set.  With timing on, the upload, the AO pass,
 * the blur and the read-back have GL times. */
static void test_gl_resources_reused(void **state)
{
    (void)state;
    obs_ctx *ctx = NULL;
    obs_ctx_desc desc = {0};
    char err[OBS_ERR_LEN] = "";
    if (obs_ctx_create(&desc, &ctx, err) != OBS_OK) {
        print_message("no GL context (%s): skipped\n", err);
        skip();
    }
    obs_deep_image d;
    obs_deep_result a, b;
    obs_params p = {0};
    assert_int_equal(obs_deep_read_exr(FIXTURE, NULL, &d, err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "radius", "1", err), OBS_OK);
    unsigned long before = ctx->gl_objects_created;
    assert_int_equal(obs_deep_run(ctx, &d, &p, &a, err), OBS_OK);
    unsigned long first = ctx->gl_objects_created - before;
    /* three node arrays (positions, normals, interval ends), three RG planes (front, blend, the blur's
     * intermediate), the pass's framebuffer and one per plane */
    assert_int_equal(first, 10);
    assert_int_equal(obs_deep_run(ctx, &d, &p, &b, err), OBS_OK);
    assert_int_equal(ctx->gl_objects_created - before, first);
    size_t n = (size_t)d.width * d.height * sizeof(float);
    assert_memory_equal(a.ao_blend.data, b.ao_blend.data, n);
    assert_memory_equal(a.ao_front.data, b.ao_front.data, n);
    obs_deep_result_free(&b);

    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    assert_int_equal(obs_deep_run(ctx, &d, &p, &b, err), OBS_OK);
    assert_int_equal(ctx->gl_objects_created - before, 2 * first);
    obs_deep_result_free(&b);
    assert_int_equal(obs_param_set(&p, "deep_layers", "4", err), OBS_OK);

    obs_pass_times t;
    assert_int_equal(obs_ctx_set_timing(ctx, 1, err), OBS_OK);
    assert_int_equal(obs_ctx_last_times(ctx, &t), 0);
    assert_int_equal(obs_deep_run(ctx, &d, &p, &b, err), OBS_OK);
    assert_int_equal(ctx->gl_objects_created - before, 3 * first);
    assert_memory_equal(a.ao_blend.data, b.ao_blend.data, n);
    assert_int_equal(obs_ctx_last_times(ctx, &t), 1);
    assert_true(t.ms[OBS_PASS_UPLOAD] >= 0.0 && t.ms[OBS_PASS_AO] >= 0.0 &&
                t.ms[OBS_PASS_BLUR] >= 0.0 && t.ms[OBS_PASS_READBACK] >= 0.0);
    assert_true(t.ms[OBS_PASS_PREP] < 0.0);
    obs_deep_result_free(&a);
    obs_deep_result_free(&b);
    obs_deep_free(&d);
    obs_ctx_destroy(ctx);
}

/* ---- the blur (VAO++ 4.6, the flat chain's) -------------------------------- */

/* The energy of the 3x3 tile's pattern in a plane: the tile's rotation
 * (frame.c's rot, by x % 3 and y % 3) repeats every 3 pixels, so its
 * structure is what differs between the 9 phases' means; the sum of
 * their squared deviations from the mean, over the pixels with a node. */
static double pattern_energy(const obs_deep_image *d, const float *ao)
{
    double sum[9] = {0}, all = 0.0;
    int cnt[9] = {0}, n = 0;
    for (int y = 0; y < d->height; y++)
        for (int x = 0; x < d->width; x++) {
            size_t i = (size_t)y * d->width + x;
            if (d->offset[i + 1] == d->offset[i])
                continue;
            int k = 3 * (x % 3) + (y % 3);
            sum[k] += ao[i];
            cnt[k]++;
            all += ao[i];
            n++;
        }
    double e = 0.0;
    for (int k = 0; k < 9; k++)
        if (cnt[k])
            e += (sum[k] / cnt[k] - all / n) * (sum[k] / cnt[k] - all / n);
    return e;
}

/* Deep input takes the flat chain's blur: the 3x3 pattern's energy of
 * both planes (front node, blend) falls with it on, by more than 10 times
 * on the fixture (measured: 246 times on the front node's, 21 on the
 * blend's), and GL equals the CPU twin with it off, on and at another
 * radius. */
static void test_blur(void **state)
{
    (void)state;
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_deep_read_exr(FIXTURE, NULL, &d, err), OBS_OK);
    obs_params on = {0}, off = {0};
    assert_int_equal(obs_param_set(&on, "radius", "1", err), OBS_OK);
    off = on;
    assert_int_equal(obs_param_set(&off, "blur", "off", err), OBS_OK);
    obs_deep_result a, b;
    assert_int_equal(obs_deep_run_cpu(&d, &off, &a, err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &on, &b, err), OBS_OK);
    double ef0 = pattern_energy(&d, a.ao_front.data), ef1 = pattern_energy(&d, b.ao_front.data);
    double eb0 = pattern_energy(&d, a.ao_blend.data), eb1 = pattern_energy(&d, b.ao_blend.data);
    print_message("deep blur: 3x3 pattern energy, front %.3e -> %.3e, blend %.3e -> %.3e\n", ef0,
                  ef1, eb0, eb1);
    assert_true(ef0 > 0.0 && eb0 > 0.0);
    assert_true(ef1 < 0.1 * ef0);
    assert_true(eb1 < 0.1 * eb0);
    /* the composite follows the blurred blend */
    size_t n = (size_t)d.width * d.height;
    int changed = 0;
    for (size_t i = 0; i < n; i++)
        changed += a.composite.data[4 * i] != b.composite.data[4 * i];
    assert_true(changed > 0);
    obs_deep_result_free(&a);
    obs_deep_result_free(&b);

    obs_ctx *ctx = NULL;
    obs_ctx_desc desc = {0};
    if (obs_ctx_create(&desc, &ctx, err) != OBS_OK) {
        print_message("no GL context (%s): GL half skipped\n", err);
        obs_deep_free(&d);
        return;
    }
    compare_gl(ctx, &d, &off, "fixture, blur off");
    compare_gl(ctx, &d, &on, "fixture, blur on");
    assert_int_equal(obs_param_set(&on, "blur_radius", "7", err), OBS_OK);
    assert_int_equal(obs_param_set(&on, "deep_hull", "thin", err), OBS_OK);
    compare_gl(ctx, &d, &on, "fixture, blur radius 7, thin");
    obs_ctx_destroy(ctx);
    obs_deep_free(&d);
}

/* ---- real deep EXRs (../shared) ---------------------------------------------- */

static void test_real_files(void **state)
{
    (void)state;
    static const char *const names[] = {"Balls", "Leaves", "Trunks"};
    int found = 0;
    for (int k = 0; k < 3; k++) {
        char path[512], err[OBS_ERR_LEN] = "";
        snprintf(path, sizeof path, "%s/openexr-images/v2/LowResLeftView/%s.exr", obs_test_shared(),
                 names[k]);
        if (!obs_test_exists(path))
            continue;
        found++;
        obs_deep_image d;
        if (obs_deep_read_exr(path, NULL, &d, err) != OBS_OK)
            fail_msg("%s", err);
        assert_true(d.offset[(size_t)d.width * d.height] > 10000);
        obs_params p = {0};
        assert_int_equal(obs_param_set(&p, "fov_y", "40", err), OBS_OK);
        assert_int_equal(obs_param_set(&p, "radius", "20", err), OBS_OK);
        assert_int_equal(obs_param_set(&p, "samples", "8", err), OBS_OK);
        obs_deep_result r;
        if (obs_deep_run_cpu(&d, &p, &r, err) != OBS_OK)
            fail_msg("%s: %s", path, err);
        size_t n = (size_t)d.width * d.height;
        double mean = 0.0;
        for (size_t i = 0; i < n; i++) {
            assert_true(r.ao_blend.data[i] >= 0.0f && r.ao_blend.data[i] <= 1.0f + 1e-5f);
            mean += r.ao_blend.data[i];
        }
        print_message("%s: %dx%d, %llu samples, mean blended AO %.4f\n", names[k], d.width, d.height,
                      (unsigned long long)d.offset[n], mean / (double)n);
        obs_deep_result_free(&r);
        obs_deep_free(&d);
    }
    if (!found)
        skip();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_read_fixture),
        cmocka_unit_test(test_read_limits),
        cmocka_unit_test(test_read_damaged_fixture),
        cmocka_unit_test(test_read_damaged_files),
        cmocka_unit_test(test_compress_eq5),
        cmocka_unit_test(test_hidden_occluder),
        cmocka_unit_test(test_interval_lists),
        cmocka_unit_test(test_compress_intervals),
        cmocka_unit_test(test_intervals),
        cmocka_unit_test(test_gtao_deep),
        cmocka_unit_test(test_hbao_deep),
        cmocka_unit_test(test_gtao_intervals),
        cmocka_unit_test(test_gtao_raised_slab),
        cmocka_unit_test(test_gtao_sheet),
        cmocka_unit_test(test_gtao_cut_list),
        cmocka_unit_test(test_subpixel_sphere),
        cmocka_unit_test(test_single_is_flat),
        cmocka_unit_test(test_hidden_occluder_hemisphere),
        cmocka_unit_test(test_methods_refused),
        cmocka_unit_test(test_blend_and_hull),
        cmocka_unit_test(test_gl_twin),
        cmocka_unit_test(test_gl_resources_reused),
        cmocka_unit_test(test_blur),
        cmocka_unit_test(test_real_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
