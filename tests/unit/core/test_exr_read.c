/* G-buffer EXR input: the real Blender G-buffers, and files written here
 * with OpenEXR's C API to reach each feature (tiles, parts, pixel types,
 * data windows, compressions, camera attributes). */
#include "testutil.h"

#include <math.h>
#include <openexr.h>

#include "internal.h"
#include "obscura/io.h"

/* ---- synthetic files ---------------------------------------------------- */

typedef struct tpart {
    const char *name; /* part name; NULL for a single-part file */
    int tiled, tw, th;
    int deep;         /* deep scanline, every pixel without samples */
    exr_attr_box2i_t disp, dw;
    exr_compression_t comp;
    int nch;
    const char *ch[8];
    exr_pixel_type_t type[8];
} tpart;

/* Value of a channel at absolute pixel (x, y): small integers, exact in
 * half, different per channel name so a mix-up shows. */
static float tval(const char *name, int x, int y)
{
    unsigned h = 0;
    for (const char *p = name; *p; p++)
        h = h * 31u + (unsigned char)*p;
    return (float)(h % 97u + (unsigned)(x * 3 + y * 5 + 1000000) % 900u);
}

/* Exact for the small integers above. */
static uint16_t to_half(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    if (f == 0.0f)
        return 0;
    int e = (int)((u >> 23) & 0xff) - 127 + 15;
    return (uint16_t)(((u >> 16) & 0x8000) | ((unsigned)e << 10) | ((u >> 13) & 0x3ff));
}

static int tw_(const tpart *p) { return p->dw.max.x - p->dw.min.x + 1; }
static int th_(const tpart *p) { return p->dw.max.y - p->dw.min.y + 1; }

static void write_synth(const char *path, const tpart *parts, int nparts, const float *wtc,
                        const float *ndc)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx = NULL;
    exr_attr_v2f_t center;
    center.x = center.y = 0.0f;
    assert_int_equal(exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init), EXR_ERR_SUCCESS);
    for (int p = 0; p < nparts; p++) {
        const tpart *tp = &parts[p];
        int idx = -1;
        exr_storage_t storage = tp->deep ? EXR_STORAGE_DEEP_SCANLINE
                                : tp->tiled ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE;
        assert_int_equal(exr_add_part(ctx, tp->name, storage, &idx), 0);
        assert_int_equal(exr_initialize_required_attr(ctx, idx, &tp->disp, &tp->dw, 1.0f, &center, 1.0f,
                                                      EXR_LINEORDER_INCREASING_Y, tp->comp), 0);
        if (tp->tiled)
            assert_int_equal(exr_set_tile_descriptor(ctx, idx, (uint32_t)tp->tw, (uint32_t)tp->th,
                                                     EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN), 0);
        for (int c = 0; c < tp->nch; c++)
            assert_int_equal(exr_add_channel(ctx, idx, tp->ch[c], tp->type[c], EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), 0);
        if (wtc) {
            exr_attr_m44f_t m;
            memcpy(m.m, wtc, sizeof m.m);
            assert_int_equal(exr_attr_set_m44f(ctx, idx, "worldToCamera", &m), 0);
        }
        if (ndc) {
            exr_attr_m44f_t m;
            memcpy(m.m, ndc, sizeof m.m);
            assert_int_equal(exr_attr_set_m44f(ctx, idx, "worldToNDC", &m), 0);
        }
    }
    assert_int_equal(exr_write_header(ctx), 0);

    for (int p = 0; p < nparts; p++) {
        const tpart *tp = &parts[p];
        int w = tw_(tp), h = th_(tp);
        if (tp->deep) { /* uncompressed, no samples: a zero count table per line */
            int32_t *counts = calloc((size_t)w, sizeof *counts);
            for (int y = 0; y < h; y++)
                assert_int_equal(exr_write_deep_scanline_chunk(ctx, p, tp->dw.min.y + y, NULL, 0, 0, counts,
                                                               (uint64_t)w * sizeof *counts), 0);
            free(counts);
            continue;
        }
        void *buf[8];
        int bpe[8];
        for (int c = 0; c < tp->nch; c++) {
            bpe[c] = tp->type[c] == EXR_PIXEL_HALF ? 2 : 4;
            buf[c] = malloc((size_t)w * h * bpe[c]);
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    float v = tval(tp->ch[c], tp->dw.min.x + x, tp->dw.min.y + y);
                    size_t i = (size_t)y * w + x;
                    if (tp->type[c] == EXR_PIXEL_HALF)
                        ((uint16_t *)buf[c])[i] = to_half(v);
                    else if (tp->type[c] == EXR_PIXEL_UINT)
                        ((uint32_t *)buf[c])[i] = (uint32_t)v;
                    else
                        ((float *)buf[c])[i] = v;
                }
        }
        exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
        int started = 0, lines = 1, ntx = 1, nty;
        if (!tp->tiled)
            assert_int_equal(exr_get_scanlines_per_chunk(ctx, p, &lines), 0);
        else
            ntx = (w + tp->tw - 1) / tp->tw;
        nty = tp->tiled ? (h + tp->th - 1) / tp->th : (h + lines - 1) / lines;
        for (int ty = 0; ty < nty; ty++)
            for (int tx = 0; tx < ntx; tx++) {
                exr_chunk_info_t ci;
                int x0 = tp->tiled ? tx * tp->tw : 0, y0 = tp->tiled ? ty * tp->th : ty * lines;
                if (tp->tiled)
                    assert_int_equal(exr_write_tile_chunk_info(ctx, p, tx, ty, 0, 0, &ci), 0);
                else
                    assert_int_equal(exr_write_scanline_chunk_info(ctx, p, tp->dw.min.y + y0, &ci), 0);
                assert_int_equal(started ? exr_encoding_update(ctx, p, &ci, &enc)
                                         : exr_encoding_initialize(ctx, p, &ci, &enc), 0);
                started = 1;
                for (int k = 0; k < enc.channel_count; k++) {
                    exr_coding_channel_info_t *ch = &enc.channels[k];
                    int c = 0;
                    while (strcmp(tp->ch[c], ch->channel_name) != 0)
                        c++;
                    ch->encode_from_ptr = (const uint8_t *)buf[c] + ((size_t)y0 * w + x0) * bpe[c];
                    ch->user_pixel_stride = bpe[c];
                    ch->user_line_stride = w * bpe[c];
                    ch->user_data_type = tp->type[c];
                    ch->user_bytes_per_element = (int16_t)bpe[c];
                }
                assert_int_equal(exr_encoding_choose_default_routines(ctx, p, &enc), 0);
                assert_int_equal(exr_encoding_run(ctx, p, &enc), 0);
            }
        if (started)
            exr_encoding_destroy(ctx, &enc);
        for (int c = 0; c < tp->nch; c++)
            free(buf[c]);
    }
    assert_int_equal(exr_finish(&ctx), 0);
}

static const char *tmp_path(const char *name)
{
    static char path[4][512];
    static int i;
    i = (i + 1) % 4;
    snprintf(path[i], sizeof path[i], "%s/%s", obs_test_tmp(), name);
    return path[i];
}

static exr_attr_box2i_t box(int x0, int y0, int x1, int y1)
{
    exr_attr_box2i_t b;
    b.min.x = x0;
    b.min.y = y0;
    b.max.x = x1;
    b.max.y = y1;
    return b;
}

static tpart simple_part(int w, int h, exr_compression_t comp)
{
    tpart p = {.comp = comp};
    p.disp = p.dw = box(0, 0, w - 1, h - 1);
    return p;
}

static void add_ch(tpart *p, const char *name, exr_pixel_type_t t)
{
    p->ch[p->nch] = name;
    p->type[p->nch++] = t;
}

/* Every pixel of a plane channel equals tval() at its absolute position. */
static void check_plane(const obs_gbuffer *gb, const obs_plane *pl, int comp, const char *name,
                        int x0, int y0)
{
    for (int y = 0; y < gb->height; y++)
        for (int x = 0; x < gb->width; x++) {
            float v = obs__plane_px(pl, gb->width, x, y)[comp];
            if (v != tval(name, x0 + x, y0 + y))
                fail_msg("%s at (%d,%d): %g, expected %g", name, x, y, v, tval(name, x0 + x, y0 + y));
        }
}

/* ---- Blender G-buffers --------------------------------------------------- */

static void check_blender(const char *path)
{
    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    obs_status st = obs_gbuffer_read_exr(path, NULL, NULL, &f, err);
    if (st != OBS_OK)
        fail_msg("%s", err);
    const obs_gbuffer *gb = &f.gb;
    assert_int_equal(gb->width, 320);
    assert_int_equal(gb->height, 240);
    assert_int_equal(gb->display_x, 0);
    assert_int_equal(gb->display_y, 0);
    assert_int_equal(gb->display_width, 320);
    assert_int_equal(gb->display_height, 240);
    assert_string_equal(f.info.preset, "blender");
    assert_string_equal(f.info.depth, "ViewLayer.Depth.Z");
    assert_string_equal(f.info.normal[0], "ViewLayer.Normal.X");
    assert_string_equal(f.info.normal[1], "ViewLayer.Normal.Y");
    assert_string_equal(f.info.normal[2], "ViewLayer.Normal.Z");
    assert_string_equal(f.info.color[0], "ViewLayer.Combined.R"); /* the beauty */
    assert_string_equal(f.info.color[2], "ViewLayer.Combined.B");
    assert_string_equal(f.info.color[3], "ViewLayer.Combined.A");
    assert_string_equal(f.info.compression, "zip");
    assert_int_equal(f.info.part, 0);
    assert_int_equal(f.info.part_count, 1);
    assert_int_equal(f.info.tiled, 0);
    assert_int_equal(gb->camera.source, OBS_CAMERA_NONE); /* Blender writes no camera */
    assert_non_null(gb->normal.data);
    assert_non_null(gb->color.data);
    assert_int_equal(gb->normal.channels, 3);
    assert_int_equal(gb->color.channels, 4);

    /* Cycles averages the normal pass over a pixel's samples, so where
     * only some samples hit a surface (the ground's horizon, the walls'
     * edges) the normal is shorter than 1, never longer. */
    int sky = 0, geo = 0, unit = 0;
    for (int i = 0; i < gb->width * gb->height; i++) {
        float d = gb->depth.data[i];
        const float *n = gb->normal.data + 3 * i, *c = gb->color.data + 4 * i;
        assert_true(c[3] == 1.0f); /* Combined.A: an opaque film */
        if (d >= 1e9f) {
            assert_true(d == 1e10f); /* Blender's sky depth */
            sky++;
            continue;
        }
        assert_true(d > 0.0f && d < 1000.0f);
        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 1.0f + 1e-3f)
            fail_msg("normal at %d has length %g", i, len);
        unit += len > 1.0f - 1e-3f;
        geo++;
    }
    assert_true(geo > 1000 && sky > 1000);
    assert_true(unit > 0.85 * geo);
    print_message("%s: %d geometry pixels (%.1f%% with unit normals), %d sky pixels\n", path, geo,
                  100.0 * unit / geo, sky);
    obs_gbuffer_free(&f);
    assert_null(f.storage);
}

static void test_room(void **state)
{
    (void)state;
    check_blender(TESTDATA "/room_small.exr");
}

static void test_yard(void **state)
{
    (void)state;
    check_blender(TESTDATA "/yard_small.exr");
}

static void test_explicit_override(void **state)
{
    (void)state;
    obs_gbuffer_file f;
    obs_image pz;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map map = {.preset = "blender", .depth = "ViewLayer.Position.Z",
                           .color = {"ViewLayer.Combined.R", "ViewLayer.Combined.G",
                                     "ViewLayer.Combined.B", "ViewLayer.Combined.A"}};
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", &map, NULL, &f, err), OBS_OK);
    assert_string_equal(f.info.depth, "ViewLayer.Position.Z");
    assert_string_equal(f.info.color[3], "ViewLayer.Combined.A");
    assert_string_equal(f.info.normal[0], "ViewLayer.Normal.X");
    assert_int_equal(obs_exr_read_channel(TESTDATA "/room_small.exr", "ViewLayer.Position.Z", NULL, &pz, err), OBS_OK);
    assert_int_equal(pz.width, 320);
    assert_int_equal(pz.channels, 1);
    assert_memory_equal(pz.data, f.gb.depth.data, sizeof(float) * 320 * 240);
    obs_image_free(&pz);
    obs_gbuffer_free(&f);
}

static void test_missing_channel(void **state)
{
    (void)state;
    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map generic = {.preset = "generic"};
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", &generic, NULL, &f, err),
                     OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "room_small.exr"));
    assert_non_null(strstr(err, "Z, depth.Z, Depth.Z"));
    assert_non_null(strstr(err, "ViewLayer.AO.B")); /* what the file has */
    assert_null(f.storage);

    obs_channel_map named = {.depth = "Nope.Z"};
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", &named, NULL, &f, err),
                     OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "'Nope.Z'"));

    obs_image img;
    assert_int_equal(obs_exr_read_channel(TESTDATA "/room_small.exr", "Nope", NULL, &img, err),
                     OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "'Nope'"));
    assert_null(img.data);

    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/no_such_file.exr", NULL, NULL, &f, err), OBS_IO);
    assert_non_null(strstr(err, "no_such_file.exr"));
}

static void test_size_limit(void **state)
{
    (void)state;
    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    obs_limits small = {.max_width = 256, .max_height = 256};
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", NULL, &small, &f, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "320x240"));
    assert_null(f.storage);
    obs_limits pixels = {.max_pixels = 320 * 240 - 1};
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", NULL, &pixels, &f, err), OBS_TOO_LARGE);
    obs_image img;
    assert_int_equal(obs_exr_read_channel(TESTDATA "/room_small.exr", "ViewLayer.Depth.Z", &small, &img, err),
                     OBS_TOO_LARGE);
    obs_limits exact = {.max_width = 320, .max_height = 240, .max_pixels = 320 * 240};
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", NULL, &exact, &f, err), OBS_OK);
    obs_gbuffer_free(&f);
}

static void test_memory_equals_file(void **state)
{
    (void)state;
    obs_gbuffer_file a, b;
    char err[OBS_ERR_LEN] = "";
    size_t len;
    unsigned char *buf = obs_test_slurp(TESTDATA "/yard_small.exr", &len);
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/yard_small.exr", NULL, NULL, &a, err), OBS_OK);
    assert_int_equal(obs_gbuffer_read_exr_mem(buf, len, NULL, NULL, &b, err), OBS_OK);
    assert_int_equal(a.gb.width, b.gb.width);
    assert_int_equal(a.gb.height, b.gb.height);
    assert_memory_equal(a.storage, b.storage, sizeof(float) * 320 * 240 * 8);
    assert_memory_equal(&a.info, &b.info, sizeof a.info);
    obs_gbuffer_free(&b);
    /* a truncated buffer is an error, not a crash */
    assert_int_not_equal(obs_gbuffer_read_exr_mem(buf, len / 2, NULL, NULL, &b, err), OBS_OK);
    assert_true(err[0] != '\0');
    assert_int_equal(obs_gbuffer_read_exr_mem(buf, 0, NULL, NULL, &b, err), OBS_BAD_FILE);
    free(buf);
    obs_gbuffer_free(&a);
}

static void test_list_channels(void **state)
{
    (void)state;
    char **names = NULL;
    char err[OBS_ERR_LEN] = "";
    int n = 0;
    assert_int_equal(obs_exr_list_channels(TESTDATA "/room_small.exr", &names, err), OBS_OK);
    while (names[n])
        n++;
    assert_int_equal(n, 17);
    assert_string_equal(names[0], "ViewLayer.AO.B");
    obs_strv_free(names);
    obs_strv_free(NULL);
    assert_int_equal(obs_exr_list_channels(TESTDATA "/room_small.camera.json", &names, err), OBS_BAD_FILE);
    assert_null(names);
}

/* ---- synthesised files -------------------------------------------------- */

static void test_tiled(void **state)
{
    (void)state;
    const char *path = tmp_path("tiled.exr");
    tpart p = simple_part(50, 37, EXR_COMPRESSION_ZIP);
    p.tiled = 1;
    p.tw = 16;
    p.th = 16;
    add_ch(&p, "B", EXR_PIXEL_FLOAT);
    add_ch(&p, "G", EXR_PIXEL_FLOAT);
    add_ch(&p, "R", EXR_PIXEL_FLOAT);
    add_ch(&p, "Z", EXR_PIXEL_FLOAT);
    write_synth(path, &p, 1, NULL, NULL);

    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    if (obs_gbuffer_read_exr(path, NULL, NULL, &f, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(f.info.tiled, 1);
    assert_string_equal(f.info.preset, "generic");
    assert_int_equal(f.gb.width, 50);
    assert_int_equal(f.gb.height, 37);
    assert_null(f.gb.normal.data);
    check_plane(&f.gb, &f.gb.depth, 0, "Z", 0, 0);
    check_plane(&f.gb, &f.gb.color, 0, "R", 0, 0);
    check_plane(&f.gb, &f.gb.color, 1, "G", 0, 0);
    check_plane(&f.gb, &f.gb.color, 2, "B", 0, 0);
    for (int i = 0; i < 50 * 37; i++)
        assert_true(f.gb.color.data[4 * i + 3] == 1.0f); /* no A: opaque */
    obs_gbuffer_free(&f);
}

static void test_multipart(void **state)
{
    (void)state;
    const char *path = tmp_path("multipart.exr");
    tpart p[2] = {simple_part(24, 20, EXR_COMPRESSION_ZIPS), simple_part(24, 20, EXR_COMPRESSION_PIZ)};
    p[0].name = "beauty";
    add_ch(&p[0], "B", EXR_PIXEL_HALF);
    add_ch(&p[0], "G", EXR_PIXEL_HALF);
    add_ch(&p[0], "R", EXR_PIXEL_HALF);
    p[1].name = "gbuffer";
    add_ch(&p[1], "N.X", EXR_PIXEL_FLOAT);
    add_ch(&p[1], "N.Y", EXR_PIXEL_FLOAT);
    add_ch(&p[1], "N.Z", EXR_PIXEL_FLOAT);
    add_ch(&p[1], "Z", EXR_PIXEL_FLOAT);
    write_synth(path, p, 2, NULL, NULL);

    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    if (obs_gbuffer_read_exr(path, NULL, NULL, &f, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(f.info.part, 1);
    assert_int_equal(f.info.part_count, 2);
    assert_string_equal(f.info.compression, "piz");
    assert_string_equal(f.info.normal[1], "N.Y");
    assert_null(f.gb.color.data); /* colour lives in another part */
    check_plane(&f.gb, &f.gb.depth, 0, "Z", 0, 0);
    check_plane(&f.gb, &f.gb.normal, 0, "N.X", 0, 0);
    check_plane(&f.gb, &f.gb.normal, 2, "N.Z", 0, 0);
    obs_gbuffer_free(&f);

    /* missing everywhere: the message lists both parts' channels */
    obs_channel_map map = {.depth = "depth"};
    assert_int_equal(obs_gbuffer_read_exr(path, &map, NULL, &f, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "'depth'"));
    assert_non_null(strstr(err, "B, G, R, N.X"));

    /* a single channel from whichever part holds it */
    obs_image img;
    assert_int_equal(obs_exr_read_channel(path, "G", NULL, &img, err), OBS_OK);
    assert_true(img.data[5] == tval("G", 5, 0));
    obs_image_free(&img);
}

static void test_half_uint_window(void **state)
{
    (void)state;
    const char *path = tmp_path("window.exr");
    tpart p = simple_part(100, 80, EXR_COMPRESSION_RLE);
    p.dw = box(10, 20, 59, 49);
    add_ch(&p, "A", EXR_PIXEL_HALF);
    add_ch(&p, "B", EXR_PIXEL_HALF);
    add_ch(&p, "G", EXR_PIXEL_HALF);
    add_ch(&p, "R", EXR_PIXEL_HALF);
    add_ch(&p, "Z", EXR_PIXEL_UINT);
    add_ch(&p, "normal.X", EXR_PIXEL_HALF);
    add_ch(&p, "normal.Y", EXR_PIXEL_FLOAT);
    add_ch(&p, "normal.Z", EXR_PIXEL_UINT);
    write_synth(path, &p, 1, NULL, NULL);

    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    if (obs_gbuffer_read_exr(path, NULL, NULL, &f, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(f.gb.width, 50);
    assert_int_equal(f.gb.height, 30);
    assert_int_equal(f.gb.display_x, 10);
    assert_int_equal(f.gb.display_y, 20);
    assert_int_equal(f.gb.display_width, 100);
    assert_int_equal(f.gb.display_height, 80);
    check_plane(&f.gb, &f.gb.depth, 0, "Z", 10, 20);
    check_plane(&f.gb, &f.gb.normal, 0, "normal.X", 10, 20);
    check_plane(&f.gb, &f.gb.normal, 1, "normal.Y", 10, 20);
    check_plane(&f.gb, &f.gb.normal, 2, "normal.Z", 10, 20);
    check_plane(&f.gb, &f.gb.color, 0, "R", 10, 20);
    check_plane(&f.gb, &f.gb.color, 3, "A", 10, 20);
    obs_gbuffer_free(&f);

    /* display window not at the origin */
    p.disp = box(-5, -7, 94, 72);
    write_synth(path, &p, 1, NULL, NULL);
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &f, err), OBS_OK);
    assert_int_equal(f.gb.display_x, 15);
    assert_int_equal(f.gb.display_y, 27);
    obs_gbuffer_free(&f);
}

/* OpenEXR 3.1 writes through NULL destinations in its half-to-float fast
 * paths for 3- and 4-channel parts; reading one channel of such a part
 * must still work. */
static void test_half_subset(void **state)
{
    (void)state;
    const char *path = tmp_path("rgba_half.exr");
    tpart p = simple_part(33, 17, EXR_COMPRESSION_ZIP);
    add_ch(&p, "A", EXR_PIXEL_HALF);
    add_ch(&p, "B", EXR_PIXEL_HALF);
    add_ch(&p, "G", EXR_PIXEL_HALF);
    add_ch(&p, "R", EXR_PIXEL_HALF);
    write_synth(path, &p, 1, NULL, NULL);
    char err[OBS_ERR_LEN] = "";
    static const char *const chans[] = {"A", "B", "G", "R"};
    for (int c = 0; c < 4; c++) {
        obs_image img;
        assert_int_equal(obs_exr_read_channel(path, chans[c], NULL, &img, err), OBS_OK);
        for (int y = 0; y < 17; y++)
            for (int x = 0; x < 33; x++)
                assert_true(img.data[y * 33 + x] == tval(chans[c], x, y));
        obs_image_free(&img);
    }
    obs_gbuffer_file f;
    obs_channel_map map = {.depth = "R", .normal = {"A", "B", "G"}};
    assert_int_equal(obs_gbuffer_read_exr(path, &map, NULL, &f, err), OBS_OK);
    check_plane(&f.gb, &f.gb.depth, 0, "R", 0, 0);
    check_plane(&f.gb, &f.gb.normal, 1, "B", 0, 0);
    obs_gbuffer_free(&f);
    obs_channel_map one = {.depth = "G"};
    assert_int_equal(obs_gbuffer_read_exr(path, &one, NULL, &f, err), OBS_OK);
    check_plane(&f.gb, &f.gb.depth, 0, "G", 0, 0);
    obs_gbuffer_free(&f);
}

static void test_compressions(void **state)
{
    (void)state;
    static const exr_compression_t comps[] = {
        EXR_COMPRESSION_NONE, EXR_COMPRESSION_RLE, EXR_COMPRESSION_ZIPS, EXR_COMPRESSION_ZIP,
        EXR_COMPRESSION_PIZ, EXR_COMPRESSION_PXR24, EXR_COMPRESSION_B44, EXR_COMPRESSION_B44A};
    static const char *const names[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a"};
    for (int i = 0; i < 8; i++) {
        const char *path = tmp_path("comp.exr");
        tpart p = simple_part(40, 40, comps[i]);
        add_ch(&p, "N.B", EXR_PIXEL_HALF);
        add_ch(&p, "N.G", EXR_PIXEL_HALF);
        add_ch(&p, "N.R", EXR_PIXEL_HALF);
        add_ch(&p, "Z", EXR_PIXEL_FLOAT);
        write_synth(path, &p, 1, NULL, NULL);
        obs_gbuffer_file f;
        char err[OBS_ERR_LEN] = "";
        if (obs_gbuffer_read_exr(path, NULL, NULL, &f, err) != OBS_OK)
            fail_msg("%s: %s", names[i], err);
        assert_string_equal(f.info.compression, names[i]);
        check_plane(&f.gb, &f.gb.depth, 0, "Z", 0, 0); /* float: B44 leaves it alone */
        /* B44 is lossy for half: compare loosely there */
        for (int k = 0; k < 40 * 40; k++) {
            float v = f.gb.normal.data[3 * k], want = tval("N.R", k % 40, k / 40);
            assert_true(fabsf(v - want) <= (i >= 6 ? 0.05f * want + 1.0f : 0.0f));
        }
        obs_gbuffer_free(&f);
    }
}

/* Patches the compression attribute's value byte of a file on disk. */
static void patch_compression(const char *path, unsigned char value)
{
    size_t len;
    unsigned char *buf = obs_test_slurp(path, &len);
    static const char key[] = "compression\0compression"; /* name, type */
    size_t klen = sizeof key; /* includes the type's NUL */
    size_t at = 0;
    while (at + klen + 5 <= len && memcmp(buf + at, key, klen) != 0)
        at++;
    assert_true(at + klen + 5 <= len);
    buf[at + klen + 4] = value; /* after the int32 size */
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(buf, 1, len, fp), len);
    fclose(fp);
    free(buf);
}

static void test_dwa_unsupported(void **state)
{
    (void)state;
    const char *path = tmp_path("dwa.exr");
    tpart p = simple_part(16, 16, EXR_COMPRESSION_ZIP);
    add_ch(&p, "Z", EXR_PIXEL_FLOAT);
    static const struct { unsigned char v; const char *name; } dwa[] = {
        {EXR_COMPRESSION_DWAA, "DWAA"}, {EXR_COMPRESSION_DWAB, "DWAB"}};
    for (int i = 0; i < 2; i++) {
        write_synth(path, &p, 1, NULL, NULL);
        patch_compression(path, dwa[i].v);
        obs_gbuffer_file f;
        obs_image img;
        char err[OBS_ERR_LEN] = "";
        assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &f, err), OBS_UNSUPPORTED);
        assert_non_null(strstr(err, dwa[i].name));
        assert_non_null(strstr(err, "OpenEXR 3.1"));
        assert_int_equal(obs_exr_read_channel(path, "Z", NULL, &img, err), OBS_UNSUPPORTED);
        assert_non_null(strstr(err, dwa[i].name));
    }
}

static void test_deep_unsupported(void **state)
{
    (void)state;
    const char *path = tmp_path("deep.exr");
    tpart p = simple_part(8, 8, EXR_COMPRESSION_NONE);
    p.deep = 1;
    add_ch(&p, "Z", EXR_PIXEL_FLOAT);
    write_synth(path, &p, 1, NULL, NULL);
    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &f, err), OBS_UNSUPPORTED);
    assert_non_null(strstr(err, "deep"));

    char real[512];
    snprintf(real, sizeof real, "%s/openexr-images/v2/LowResLeftView/Balls.exr", obs_test_shared());
    if (obs_test_exists(real)) {
        assert_int_equal(obs_gbuffer_read_exr(real, NULL, NULL, &f, err), OBS_UNSUPPORTED);
        assert_non_null(strstr(err, "deep"));
    }
}

/* A hand-made EXR camera at the origin looking down +Z (EXR convention):
 * our view must be the same camera looking down -Z, and our projection
 * OpenGL's for the same field of view. */
static void test_camera_from_header(void **state)
{
    (void)state;
    const float f = 2.0f, aspect = 1.5f;
    const float wtc[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    /* row-vector: ndc_x = 0.5 + 0.5 f/a x/z, ndc_y = 0.5 - 0.5 f y/z, w = z */
    const float ndc[16] = {0.5f * f / aspect, 0, 0, 0, 0, -0.5f * f, 0, 0, 0.5f, 0.5f, 0, 1, 0, 0, 0, 0};
    const char *path = tmp_path("camera.exr");
    tpart p = simple_part(30, 20, EXR_COMPRESSION_ZIP);
    add_ch(&p, "Z", EXR_PIXEL_FLOAT);
    write_synth(path, &p, 1, wtc, ndc);

    obs_gbuffer_file g;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &g, err), OBS_OK);
    const obs_camera *cam = &g.gb.camera;
    assert_int_equal(cam->source, OBS_CAMERA_EXR_HEADER);
    assert_int_equal(cam->has_world_to_camera, 1);
    assert_int_equal(cam->has_projection, 1);
    const float flip[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};
    for (int i = 0; i < 16; i++)
        assert_float_equal(cam->world_to_camera[i], flip[i], 1e-6);
    obs_camera gl;
    obs_camera_from_fov((float)(2.0 * atan(1.0 / f) * 180.0 / 3.14159265358979323846), aspect, 0.1f, 1000.0f, &gl);
    for (int i = 0; i < 16; i++)
        assert_float_equal(cam->projection[i], gl.projection[i], 1e-5);
    obs_gbuffer_free(&g);

    /* worldToCamera alone: a view but no projection */
    write_synth(path, &p, 1, wtc, NULL);
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &g, err), OBS_OK);
    assert_int_equal(g.gb.camera.has_world_to_camera, 1);
    assert_int_equal(g.gb.camera.has_projection, 0);
    obs_gbuffer_free(&g);
}

static void test_beachball(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/openexr-images/Beachball/singlepart.0001.exr", obs_test_shared());
    if (!obs_test_exists(path)) {
        print_message("skipped: %s is absent\n", path);
        skip();
    }
    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map generic = {.preset = "generic"};
    if (obs_gbuffer_read_exr(path, &generic, NULL, &f, err) != OBS_OK)
        fail_msg("%s", err);
    assert_string_equal(f.info.preset, "generic");
    assert_string_equal(f.info.depth, "Z");
    assert_string_equal(f.info.color[0], "R");
    assert_string_equal(f.info.color[3], "A");
    assert_null(f.gb.normal.data);
    assert_non_null(f.gb.color.data);
    /* data window (654,245)-(1564,1120) in a 2048x1556 display window */
    assert_int_equal(f.gb.display_x, 654);
    assert_int_equal(f.gb.display_y, 245);
    assert_int_equal(f.gb.width, 911);
    assert_int_equal(f.gb.height, 876);
    assert_int_equal(f.gb.display_width, 2048);
    assert_int_equal(f.gb.display_height, 1556);
    int covered = 0;
    for (int i = 0; i < f.gb.width * f.gb.height; i++) {
        assert_true(isfinite(f.gb.depth.data[i]));
        covered += f.gb.color.data[4 * i + 3] > 0.5f;
    }
    assert_true(covered > 1000);
    obs_gbuffer_free(&f);
}

/* ---- parallel decoding --------------------------------------------------- */

static size_t storage_bytes(const obs_gbuffer_file *f)
{
    size_t per = 1 + (f->gb.normal.data ? 3 : 0) + (f->gb.color.data ? 4 : 0);
    return (size_t)f->gb.width * (size_t)f->gb.height * per * sizeof(float);
}

/* The same file read with one decode thread and with `threads`: same
 * status, message, planes and info. */
static void same_with_threads(const char *path, const unsigned char *buf, size_t len,
                              const obs_channel_map *map, int threads)
{
    obs_limits one = {.threads = 1}, many = {.threads = threads};
    obs_gbuffer_file a, b;
    char ea[OBS_ERR_LEN] = "", eb[OBS_ERR_LEN] = "";
    obs_status sa = buf ? obs_gbuffer_read_exr_mem(buf, len, map, &one, &a, ea)
                        : obs_gbuffer_read_exr(path, map, &one, &a, ea);
    obs_status sb = buf ? obs_gbuffer_read_exr_mem(buf, len, map, &many, &b, eb)
                        : obs_gbuffer_read_exr(path, map, &many, &b, eb);
    if (sa != sb || strcmp(ea, eb) != 0)
        fail_msg("%s (%zu bytes): 1 thread: %s (%s); %d threads: %s (%s)", path, len,
                 obs_status_name(sa), ea, threads, obs_status_name(sb), eb);
    if (sa == OBS_OK) {
        assert_int_equal(a.gb.width, b.gb.width);
        assert_int_equal(a.gb.height, b.gb.height);
        assert_int_equal(storage_bytes(&a), storage_bytes(&b));
        assert_memory_equal(a.storage, b.storage, storage_bytes(&a));
        assert_memory_equal(&a.info, &b.info, sizeof a.info);
    }
    obs_gbuffer_free(&a);
    obs_gbuffer_free(&b);
}

static void test_threads_blender(void **state)
{
    (void)state;
    const char *files[] = {TESTDATA "/room_small.exr", TESTDATA "/yard_small.exr"};
    for (int i = 0; i < 2; i++) {
        size_t len;
        unsigned char *buf = obs_test_slurp(files[i], &len);
        for (int n = 2; n <= 8; n *= 2) {
            same_with_threads(files[i], NULL, 0, NULL, n);
            same_with_threads(files[i], buf, len, NULL, n);
        }
        /* damage: cut short, every decoder count reports the same chunk */
        for (int k = 1; k < 8; k++)
            same_with_threads(files[i], buf, len * (size_t)k / 8, NULL, 4);
        /* one compressed chunk overwritten in the middle */
        memset(buf + len / 2, 0x5a, 64);
        same_with_threads(files[i], buf, len, NULL, 4);
        free(buf);
    }
}

static void test_threads_synth(void **state)
{
    (void)state;
    const char *tiled = tmp_path("tiled_threads.exr");
    tpart p = simple_part(50, 37, EXR_COMPRESSION_ZIP);
    p.tiled = 1;
    p.tw = 8;
    p.th = 8; /* 7 x 5 tiles */
    add_ch(&p, "B", EXR_PIXEL_HALF);
    add_ch(&p, "G", EXR_PIXEL_FLOAT);
    add_ch(&p, "R", EXR_PIXEL_FLOAT);
    add_ch(&p, "Z", EXR_PIXEL_FLOAT);
    write_synth(tiled, &p, 1, NULL, NULL);
    same_with_threads(tiled, NULL, 0, NULL, 4);
    same_with_threads(tiled, NULL, 0, NULL, 64);

    const char *multi = tmp_path("multipart_threads.exr");
    tpart mp[2] = {simple_part(24, 40, EXR_COMPRESSION_ZIP), simple_part(24, 40, EXR_COMPRESSION_ZIPS)};
    mp[0].name = "beauty";
    add_ch(&mp[0], "B", EXR_PIXEL_HALF);
    add_ch(&mp[0], "G", EXR_PIXEL_HALF);
    add_ch(&mp[0], "R", EXR_PIXEL_HALF);
    mp[1].name = "gbuffer"; /* one scanline a chunk: 40 chunks */
    add_ch(&mp[1], "N.X", EXR_PIXEL_FLOAT);
    add_ch(&mp[1], "N.Y", EXR_PIXEL_FLOAT);
    add_ch(&mp[1], "N.Z", EXR_PIXEL_FLOAT);
    add_ch(&mp[1], "Z", EXR_PIXEL_FLOAT);
    write_synth(multi, mp, 2, NULL, NULL);
    same_with_threads(multi, NULL, 0, NULL, 4);

    /* and the values are right with many threads */
    obs_limits many = {.threads = 8};
    obs_gbuffer_file f;
    char err[OBS_ERR_LEN] = "";
    if (obs_gbuffer_read_exr(tiled, NULL, &many, &f, err) != OBS_OK)
        fail_msg("%s", err);
    check_plane(&f.gb, &f.gb.depth, 0, "Z", 0, 0);
    check_plane(&f.gb, &f.gb.color, 0, "R", 0, 0);
    check_plane(&f.gb, &f.gb.color, 2, "B", 0, 0);
    obs_gbuffer_free(&f);
    if (obs_gbuffer_read_exr(multi, NULL, &many, &f, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(f.info.part, 1);
    check_plane(&f.gb, &f.gb.depth, 0, "Z", 0, 0);
    check_plane(&f.gb, &f.gb.normal, 1, "N.Y", 0, 0);
    obs_gbuffer_free(&f);
    obs_image img;
    if (obs_exr_read_channel(multi, "N.Z", &many, &img, err) != OBS_OK)
        fail_msg("%s", err);
    for (int y = 0; y < 40; y++)
        for (int x = 0; x < 24; x++)
            assert_true(img.data[y * 24 + x] == tval("N.Z", x, y));
    obs_image_free(&img);
}

/* ---- by rows (obs_gbuffer_rows_*) ---------------------------------------- */

static void same_rows(const obs_plane *a, const obs_plane *whole, int width, int y0, int y1)
{
    if (!whole->data) {
        assert_null(a->data);
        return;
    }
    const size_t row = (size_t)width * (size_t)whole->channels;
    if (memcmp(a->data, whole->data + (size_t)y0 * row, (size_t)(y1 - y0) * row * sizeof(float)) != 0)
        fail_msg("rows %d-%d differ from the whole read's", y0, y1);
}

/* Ranges down the frame overlapping the last (rows kept), one larger
 * than any before, one back up: each the whole read's rows. */
static void check_rows(const char *path)
{
    obs_gbuffer_file whole, meta;
    obs_gbuffer_rows *r;
    obs_gbuffer g;
    char err[OBS_ERR_LEN] = "";
    if (obs_gbuffer_read_exr(path, NULL, NULL, &whole, err) != OBS_OK ||
        obs_gbuffer_rows_open(path, NULL, NULL, &r, &meta, err) != OBS_OK)
        fail_msg("%s: %s", path, err);
    const int H = whole.gb.height;
    assert_int_equal(meta.gb.width, whole.gb.width);
    assert_int_equal(H, meta.gb.height);
    assert_null(meta.gb.depth.data);
    assert_int_equal(meta.gb.color.channels, whole.gb.color.data ? 4 : 0);
    assert_string_equal(meta.info.preset, whole.info.preset);
    const int ranges[][2] = {{0, H / 3}, {H / 5, H / 2}, {H / 3, H}, {1, H}, {H / 2, H / 2 + 3}, {0, 1}};
    for (size_t k = 0; k < sizeof ranges / sizeof ranges[0]; k++) {
        const int y0 = ranges[k][0], y1 = ranges[k][1];
        if (obs_gbuffer_rows_read(r, y0, y1, &g, err) != OBS_OK)
            fail_msg("%s rows %d-%d: %s", path, y0, y1, err);
        same_rows(&g.depth, &whole.gb.depth, g.width, y0, y1);
        same_rows(&g.normal, &whole.gb.normal, g.width, y0, y1);
        same_rows(&g.color, &whole.gb.color, g.width, y0, y1);
    }
    assert_int_equal(obs_gbuffer_rows_read(r, 3, 2, &g, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_gbuffer_rows_read(r, 0, H + 1, &g, err), OBS_INVALID_ARGUMENT);
    obs_gbuffer_rows_close(r);
    obs_gbuffer_free(&meta);
    obs_gbuffer_free(&whole);
}

static void test_rows(void **state)
{
    (void)state;
    check_rows(TESTDATA "/room_small.exr");
    const char *path = tmp_path("rows_tiled.exr");
    tpart p = simple_part(50, 37, EXR_COMPRESSION_ZIP);
    p.tiled = 1;
    p.tw = 16;
    p.th = 8;
    add_ch(&p, "B", EXR_PIXEL_FLOAT);
    add_ch(&p, "G", EXR_PIXEL_HALF);
    add_ch(&p, "R", EXR_PIXEL_FLOAT);
    add_ch(&p, "Z", EXR_PIXEL_FLOAT);
    write_synth(path, &p, 1, NULL, NULL);
    check_rows(path);
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_room),
        cmocka_unit_test(test_yard),
        cmocka_unit_test(test_explicit_override),
        cmocka_unit_test(test_missing_channel),
        cmocka_unit_test(test_size_limit),
        cmocka_unit_test(test_memory_equals_file),
        cmocka_unit_test(test_list_channels),
        cmocka_unit_test(test_tiled),
        cmocka_unit_test(test_multipart),
        cmocka_unit_test(test_half_uint_window),
        cmocka_unit_test(test_half_subset),
        cmocka_unit_test(test_compressions),
        cmocka_unit_test(test_dwa_unsupported),
        cmocka_unit_test(test_deep_unsupported),
        cmocka_unit_test(test_camera_from_header),
        cmocka_unit_test(test_beachball),
        cmocka_unit_test(test_threads_blender),
        cmocka_unit_test(test_threads_synth),
        cmocka_unit_test(test_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
