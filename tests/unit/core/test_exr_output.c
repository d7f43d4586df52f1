/* EXR output that keeps its input's header (obs_exr_write_ex): windows
 * from the options or the input, every header attribute type carried,
 * the layout's and multiView not, the input's camera before ours;
 * --layer names; --append with every part and channel of the input
 * unchanged in its own type (tiled, multi-part, half/float/uint, a lossy
 * compression), and its refusals. */
#include "testutil.h"

#include <openexr.h>

#include "obscura/io.h"

static const char *tmp_path(const char *name)
{
    static char path[4][512];
    static int i;
    i = (i + 1) % 4;
    snprintf(path[i], sizeof path[i], "%s/%s", obs_test_tmp(), name);
    return path[i];
}

/* ---- inputs written with OpenEXR's C API -------------------------------- */

typedef struct in_part {
    const char *name;
    exr_storage_t storage;
    int x0, y0, w, h;            /* data window */
    int dx0, dy0, dx1, dy1;      /* display window */
    exr_compression_t comp;
    int nch;
    const char *ch[4];
    exr_pixel_type_t type[4];
} in_part;

/* A value per channel and absolute pixel, exact in half and uint. */
static float val(const char *name, int x, int y)
{
    return (float)((strlen(name) * 7u + (unsigned)(x * 3 + y * 11 + 4000)) % 1000u) / 4.0f;
}

static uint16_t half_of(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    if (f == 0.0f)
        return 0;
    return (uint16_t)(((u >> 16) & 0x8000) | ((((u >> 23) & 0xff) - 112) << 10) | ((u >> 13) & 0x3ff));
}

/* Every attribute type the copier knows, on part `p`. */
static void add_attrs(exr_context_t ctx, int p)
{
    exr_attr_m44f_t m = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5f, -2, 3, 1}};
    exr_attr_m44d_t md = {{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16}};
    exr_attr_m33f_t m3 = {{1, 2, 3, 4, 5, 6, 7, 8, 9}};
    exr_attr_v2f_t v2;
    exr_attr_v3f_t v3;
    exr_attr_v2i_t v2i;
    exr_attr_box2i_t b;
    v2.x = 1.5f, v2.y = -2.5f;
    v3.x = 1, v3.y = 2, v3.z = 3;
    v2i.x = 7, v2i.y = -8;
    b.min.x = 1, b.min.y = 2, b.max.x = 3, b.max.y = 4;
    exr_attr_rational_t r = {24000, 1001};
    exr_attr_timecode_t tc = {0x01020304u, 5u};
    exr_attr_chromaticities_t chr = {0.64f, 0.33f, 0.3f, 0.6f, 0.15f, 0.06f, 0.3127f, 0.329f};
    const float fv[3] = {0.25f, 0.5f, 0.75f};
    const char *views[2] = {"left", "right"};
    assert_int_equal(exr_attr_set_string(ctx, p, "arnold/version", "7.1.4"), 0);
    assert_int_equal(exr_attr_set_string(ctx, p, "a_long_renderer_attribute_name_over_31", "long"), 0);
    assert_int_equal(exr_attr_set_m44f(ctx, p, "worldToCamera", &m), 0);
    assert_int_equal(exr_attr_set_m44d(ctx, p, "vray/cameraTransform", &md), 0);
    assert_int_equal(exr_attr_set_m33f(ctx, p, "m33", &m3), 0);
    assert_int_equal(exr_attr_set_float(ctx, p, "rs/camera/fov", 54.5f), 0);
    assert_int_equal(exr_attr_set_double(ctx, p, "d", 1.0 / 3.0), 0);
    assert_int_equal(exr_attr_set_int(ctx, p, "i", -42), 0);
    assert_int_equal(exr_attr_set_v2f(ctx, p, "v2f", &v2), 0);
    assert_int_equal(exr_attr_set_v3f(ctx, p, "v3f", &v3), 0);
    assert_int_equal(exr_attr_set_v2i(ctx, p, "v2i", &v2i), 0);
    assert_int_equal(exr_attr_set_box2i(ctx, p, "box", &b), 0);
    assert_int_equal(exr_attr_set_rational(ctx, p, "framesPerSecond", &r), 0);
    assert_int_equal(exr_attr_set_timecode(ctx, p, "timeCode", &tc), 0);
    assert_int_equal(exr_attr_set_chromaticities(ctx, p, "chromaticities", &chr), 0);
    assert_int_equal(exr_attr_set_float_vector(ctx, p, "fv", 3, fv), 0);
    assert_int_equal(exr_attr_set_string_vector(ctx, p, "multiView", 2, views), 0);
    assert_int_equal(exr_attr_set_float(ctx, p, "pixelAspectRatio", 2.0f), 0);
}

static void write_input(const char *path, const in_part *parts, int np, int attrs)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx = NULL;
    exr_attr_v2f_t centre;
    centre.x = centre.y = 0.0f;
    assert_int_equal(exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init), 0);
    assert_int_equal(exr_set_longname_support(ctx, 1), 0);
    for (int p = 0; p < np; p++) {
        const in_part *ip = &parts[p];
        exr_attr_box2i_t dw;
        dw.min.x = ip->x0, dw.min.y = ip->y0, dw.max.x = ip->x0 + ip->w - 1, dw.max.y = ip->y0 + ip->h - 1;
        int idx;
        assert_int_equal(exr_add_part(ctx, ip->name, ip->storage, &idx), 0);
        exr_attr_box2i_t disp;
        disp.min.x = ip->dx0, disp.min.y = ip->dy0, disp.max.x = ip->dx1, disp.max.y = ip->dy1;
        assert_int_equal(exr_initialize_required_attr(ctx, idx, &disp, &dw, 1.0f, &centre, 1.0f,
                                                      EXR_LINEORDER_INCREASING_Y, ip->comp), 0);
        if (ip->storage == EXR_STORAGE_TILED)
            assert_int_equal(exr_set_tile_descriptor(ctx, idx, 8, 8, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN), 0);
        for (int c = 0; c < ip->nch; c++)
            assert_int_equal(exr_add_channel(ctx, idx, ip->ch[c], ip->type[c], EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), 0);
        if (attrs)
            add_attrs(ctx, idx);
    }
    assert_int_equal(exr_write_header(ctx), 0);
    for (int p = 0; p < np; p++) {
        const in_part *ip = &parts[p];
        if (ip->storage == EXR_STORAGE_DEEP_SCANLINE) {
            int32_t *counts = calloc((size_t)ip->w, sizeof *counts);
            for (int y = 0; y < ip->h; y++)
                assert_int_equal(exr_write_deep_scanline_chunk(ctx, p, ip->y0 + y, NULL, 0, 0, counts,
                                                               (uint64_t)ip->w * sizeof *counts), 0);
            free(counts);
            continue;
        }
        uint8_t *buf[4];
        int bpe[4];
        for (int c = 0; c < ip->nch; c++) {
            bpe[c] = ip->type[c] == EXR_PIXEL_HALF ? 2 : 4;
            buf[c] = malloc((size_t)ip->w * ip->h * bpe[c]);
            for (int i = 0; i < ip->w * ip->h; i++) {
                float v = val(ip->ch[c], ip->x0 + i % ip->w, ip->y0 + i / ip->w);
                uint16_t hv = half_of(v);
                uint32_t uv = (uint32_t)(v * 4.0f);
                memcpy(buf[c] + (size_t)i * bpe[c], ip->type[c] == EXR_PIXEL_HALF ? (void *)&hv
                                                    : ip->type[c] == EXR_PIXEL_UINT ? (void *)&uv : (void *)&v,
                       (size_t)bpe[c]);
            }
        }
        int tiled = ip->storage == EXR_STORAGE_TILED, lines = 8;
        if (!tiled)
            assert_int_equal(exr_get_scanlines_per_chunk(ctx, p, &lines), 0);
        int ntx = tiled ? (ip->w + 7) / 8 : 1, nty = (ip->h + (tiled ? 8 : lines) - 1) / (tiled ? 8 : lines);
        exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
        int started = 0;
        for (int ty = 0; ty < nty; ty++)
            for (int tx = 0; tx < ntx; tx++) {
                exr_chunk_info_t ci;
                int x = tiled ? tx * 8 : 0, y = ty * (tiled ? 8 : lines);
                assert_int_equal(tiled ? exr_write_tile_chunk_info(ctx, p, tx, ty, 0, 0, &ci)
                                       : exr_write_scanline_chunk_info(ctx, p, ip->y0 + y, &ci), 0);
                assert_int_equal(started ? exr_encoding_update(ctx, p, &ci, &enc) : exr_encoding_initialize(ctx, p, &ci, &enc), 0);
                started = 1;
                for (int k = 0; k < enc.channel_count; k++) {
                    int c = 0;
                    while (strcmp(ip->ch[c], enc.channels[k].channel_name))
                        c++;
                    enc.channels[k].encode_from_ptr = buf[c] + ((size_t)y * ip->w + x) * bpe[c];
                    enc.channels[k].user_pixel_stride = bpe[c];
                    enc.channels[k].user_line_stride = ip->w * bpe[c];
                    enc.channels[k].user_data_type = ip->type[c];
                    enc.channels[k].user_bytes_per_element = (int16_t)bpe[c];
                }
                assert_int_equal(exr_encoding_choose_default_routines(ctx, p, &enc), 0);
                assert_int_equal(exr_encoding_run(ctx, p, &enc), 0);
            }
        if (started)
            exr_encoding_destroy(ctx, &enc);
        for (int c = 0; c < ip->nch; c++)
            free(buf[c]);
    }
    assert_int_equal(exr_finish(&ctx), 0);
}

static exr_context_t open_exr(const char *path)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx = NULL;
    assert_int_equal(exr_start_read(&ctx, path, &init), 0);
    return ctx;
}

/* An AO image of w x h with a value per pixel. */
static float *ao_pixels(int w, int h)
{
    float *d = malloc((size_t)w * h * sizeof *d);
    for (int i = 0; i < w * h; i++)
        d[i] = (float)(i % 17) / 16.0f;
    return d;
}

static const in_part cropped = {.storage = EXR_STORAGE_SCANLINE, .x0 = 3, .y0 = 4, .w = 10, .h = 8,
                                .dx0 = -2, .dy0 = -1, .dx1 = 29, .dy1 = 19, .comp = EXR_COMPRESSION_ZIP, .nch = 2,
                                .ch = {"Z", "N.X"}, .type = {EXR_PIXEL_FLOAT, EXR_PIXEL_HALF}};

/* obs_exr_write_ex_mem() with the input `in` in memory, the options
 * otherwise `o`'s: the bytes of the file `out` written with `o`. */
static void same_from_memory(const char *in, const char *out, const obs_exr_layer *l, const obs_exr_options *o)
{
    size_t len, flen;
    char err[OBS_ERR_LEN] = "";
    unsigned char *buf = obs_test_slurp(in, &len), *file = obs_test_slurp(out, &flen);
    obs_exr_source msrc = {.buf = buf, .len = len, .part = o->src->part};
    obs_exr_options mo = *o;
    obs_bytes mem;
    mo.src = &msrc;
    if (obs_exr_write_ex_mem(l, 1, &mo, &mem, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(mem.size, flen);
    assert_memory_equal(mem.data, file, flen);
    obs_bytes_free(&mem);
    free(buf);
    free(file);
}

/* ---- plain output ------------------------------------------------------- */

static void test_windows_from_options(void **state)
{
    (void)state;
    const char *path = tmp_path("win.exr");
    obs_image img = {10, 8, 1, ao_pixels(10, 8)};
    const char *names[] = {"AO.Y"};
    obs_exr_layer l = {&img, names};
    obs_exr_options o = {.display_x = 5, .display_y = 7, .display_width = 40, .display_height = 30};
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_write_ex(path, &l, 1, &o, err) != OBS_OK)
        fail_msg("%s", err);
    obs_channel_map map = {.depth = "AO.Y"};
    obs_gbuffer_file f;
    if (obs_gbuffer_read_exr(path, &map, NULL, &f, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(f.gb.width, 10);
    assert_int_equal(f.gb.display_x, 5);
    assert_int_equal(f.gb.display_y, 7);
    assert_int_equal(f.gb.display_width, 40);
    assert_int_equal(f.gb.display_height, 30);
    for (int i = 0; i < 80; i++)
        assert_true(f.gb.depth.data[i] == img.data[i]); /* k/16 is exact in half */
    obs_gbuffer_free(&f);
    free(img.data);
}

static void check_attrs(exr_context_t out, exr_context_t in, int opart, int ipart, const char *const *absent)
{
    int32_t n = 0;
    assert_int_equal(exr_get_attribute_count(in, ipart, &n), 0);
    for (int32_t i = 0; i < n; i++) {
        const exr_attribute_t *a, *b = NULL;
        int skip = 0;
        assert_int_equal(exr_get_attribute_by_index(in, ipart, EXR_ATTR_LIST_FILE_ORDER, i, &a), 0);
        for (const char *const *s = absent; *s; s++)
            skip |= !strcmp(a->name, *s);
        exr_result_t rv = exr_get_attribute_by_name(out, opart, a->name, &b);
        if (skip) {
            if (rv == EXR_ERR_SUCCESS && strcmp(a->name, "channels") && strcmp(a->name, "compression") &&
                strcmp(a->name, "dataWindow") && strcmp(a->name, "displayWindow") && strcmp(a->name, "lineOrder") &&
                strcmp(a->name, "name") && strcmp(a->name, "type") && strcmp(a->name, "chunkCount"))
                fail_msg("attribute %s was carried", a->name);
            continue;
        }
        if (rv != EXR_ERR_SUCCESS)
            fail_msg("attribute %s is missing", a->name);
        assert_int_equal(a->type, b->type);
        switch (a->type) {
        case EXR_ATTR_STRING: assert_string_equal(a->string->str, b->string->str); break;
        case EXR_ATTR_FLOAT: assert_true(a->f == b->f); break;
        case EXR_ATTR_DOUBLE: assert_true(a->d == b->d); break;
        case EXR_ATTR_INT: assert_int_equal(a->i, b->i); break;
        case EXR_ATTR_M44F: assert_memory_equal(a->m44f, b->m44f, sizeof *a->m44f); break;
        case EXR_ATTR_M44D: assert_memory_equal(a->m44d, b->m44d, sizeof *a->m44d); break;
        case EXR_ATTR_M33F: assert_memory_equal(a->m33f, b->m33f, sizeof *a->m33f); break;
        case EXR_ATTR_V2F: assert_memory_equal(a->v2f, b->v2f, sizeof *a->v2f); break;
        case EXR_ATTR_V3F: assert_memory_equal(a->v3f, b->v3f, sizeof *a->v3f); break;
        case EXR_ATTR_V2I: assert_memory_equal(a->v2i, b->v2i, sizeof *a->v2i); break;
        case EXR_ATTR_BOX2I: assert_memory_equal(a->box2i, b->box2i, sizeof *a->box2i); break;
        case EXR_ATTR_RATIONAL: assert_memory_equal(a->rational, b->rational, sizeof *a->rational); break;
        case EXR_ATTR_TIMECODE: assert_memory_equal(a->timecode, b->timecode, sizeof *a->timecode); break;
        case EXR_ATTR_CHROMATICITIES:
            assert_memory_equal(a->chromaticities, b->chromaticities, sizeof *a->chromaticities);
            break;
        case EXR_ATTR_FLOAT_VECTOR:
            assert_int_equal(a->floatvector->length, b->floatvector->length);
            assert_memory_equal(a->floatvector->arr, b->floatvector->arr, sizeof(float) * (size_t)a->floatvector->length);
            break;
        case EXR_ATTR_STRING_VECTOR:
            assert_int_equal(a->stringvector->n_strings, b->stringvector->n_strings);
            for (int k = 0; k < a->stringvector->n_strings; k++)
                assert_string_equal(a->stringvector->strings[k].str, b->stringvector->strings[k].str);
            break;
        case EXR_ATTR_COMPRESSION:
        case EXR_ATTR_LINEORDER: assert_int_equal(a->uc, b->uc); break;
        default: break;
        }
    }
}

/* The input's windows and every attribute but the layout's and
 * multiView; its worldToCamera, not the camera given. */
static void test_source_header(void **state)
{
    (void)state;
    const char *in = tmp_path("src.exr"), *out = tmp_path("srcao.exr");
    static const char *const absent[] = {"multiView", "channels", "compression", "dataWindow",
                                         "displayWindow", "lineOrder", NULL};
    write_input(in, &cropped, 1, 1);
    obs_image img = {10, 8, 1, ao_pixels(10, 8)};
    const char *names[] = {"AO.Y"};
    obs_exr_layer l = {&img, names};
    obs_camera cam;
    obs_camera_from_fov(50.0f, 1.0f, 0.1f, 100.0f, &cam);
    cam.has_world_to_camera = 1;
    obs_exr_source src = {.path = in, .part = 0};
    obs_exr_options o = {.cam = &cam, .src = &src};
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_write_ex(out, &l, 1, &o, err) != OBS_OK)
        fail_msg("%s", err);
    exr_context_t a = open_exr(in), b = open_exr(out);
    exr_attr_box2i_t dwa, dwb, da, db;
    assert_int_equal(exr_get_data_window(a, 0, &dwa), 0);
    assert_int_equal(exr_get_data_window(b, 0, &dwb), 0);
    assert_int_equal(exr_get_display_window(a, 0, &da), 0);
    assert_int_equal(exr_get_display_window(b, 0, &db), 0);
    assert_memory_equal(&dwa, &dwb, sizeof dwa);
    assert_memory_equal(&da, &db, sizeof da);
    check_attrs(b, a, 0, 0, absent);
    const exr_attribute_t *mv = NULL;
    assert_int_not_equal(exr_get_attribute_by_name(b, 0, "multiView", &mv), EXR_ERR_SUCCESS);
    /* the input has no worldToNDC: ours is not added beside its worldToCamera */
    const exr_attribute_t *ndc = NULL;
    assert_int_not_equal(exr_get_attribute_by_name(b, 0, "worldToNDC", &ndc), EXR_ERR_SUCCESS);
    exr_finish(&a);
    exr_finish(&b);

    /* the memory writer, from the input in memory: the same bytes */
    same_from_memory(in, out, &l, &o);

    /* an image of another size than the input's data window is refused */
    obs_image small = {9, 8, 1, img.data};
    obs_exr_layer ls = {&small, names};
    assert_int_equal(obs_exr_write_ex(out, &ls, 1, &o, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "data window"));
    free(img.data);
}

static void test_layer_names(void **state)
{
    (void)state;
    obs_image ao = {2, 2, 1, ao_pixels(2, 2)}, rgba = {2, 2, 4, calloc(16, sizeof(float))}, s = {2, 2, 1, ao.data};
    const char *n_ao[] = {"AO.Y"}, *n_rgba[] = {"R", "G", "B", "A"}, *n_s[] = {"Samples.Y"};
    obs_exr_layer l[3] = {{&ao, n_ao}, {&rgba, n_rgba}, {&s, n_s}};
    obs_exr_names names;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_exr_layers_rename(l, 3, "occ", &names, err), OBS_OK);
    assert_string_equal(l[0].names[0], "occ.Y");
    assert_string_equal(l[1].names[0], "occ.R");
    assert_string_equal(l[1].names[3], "occ.A");
    assert_string_equal(l[2].names[0], "occ.Samples.Y");
    static const char *const bad[] = {"", ".x", "x.", "a\tb",
                                      "a_name_that_is_far_too_long_for_a_layer_of_sixty_three_characters_",
                                      NULL};
    for (const char *const *b = bad; *b; b++) {
        assert_int_equal(obs_exr_layers_rename(l, 3, *b, &names, err), OBS_INVALID_ARGUMENT);
        assert_non_null(strstr(err, "layer name"));
    }
    free(ao.data);
    free(rgba.data);
}

/* ---- append -------------------------------------------------------------- */

/* Every channel of `in` is in `out`, in the same part, of the same type,
 * with the same values. */
static void check_unchanged(const char *in, const char *out)
{
    exr_context_t a = open_exr(in), b = open_exr(out);
    int na = 0, nb = 0;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(exr_get_count(a, &na), 0);
    assert_int_equal(exr_get_count(b, &nb), 0);
    assert_int_equal(na, nb);
    for (int p = 0; p < na; p++) {
        const exr_attr_chlist_t *ca, *cb;
        exr_attr_box2i_t da, db;
        assert_int_equal(exr_get_channels(a, p, &ca), 0);
        assert_int_equal(exr_get_channels(b, p, &cb), 0);
        assert_int_equal(exr_get_data_window(a, p, &da), 0);
        assert_int_equal(exr_get_data_window(b, p, &db), 0);
        assert_memory_equal(&da, &db, sizeof da);
        for (int c = 0; c < ca->num_channels; c++) {
            int found = 0;
            for (int k = 0; k < cb->num_channels; k++)
                if (!strcmp(ca->entries[c].name.str, cb->entries[k].name.str)) {
                    found = 1;
                    assert_int_equal(ca->entries[c].pixel_type, cb->entries[k].pixel_type);
                }
            if (!found)
                fail_msg("part %d: channel %s is missing", p, ca->entries[c].name.str);
        }
    }
    exr_finish(&a);
    exr_finish(&b);
    /* the values, through obscura's reader (the names are unique here) */
    char **names = NULL;
    exr_context_t c = open_exr(in);
    for (int p = 0; p < na; p++) {
        const exr_attr_chlist_t *cl;
        assert_int_equal(exr_get_channels(c, p, &cl), 0);
        for (int k = 0; k < cl->num_channels; k++) {
            obs_image ia, ib;
            if (obs_exr_read_channel(in, cl->entries[k].name.str, NULL, &ia, err) != OBS_OK ||
                obs_exr_read_channel(out, cl->entries[k].name.str, NULL, &ib, err) != OBS_OK)
                fail_msg("%s", err);
            assert_int_equal(ia.width, ib.width);
            for (int i = 0; i < ia.width * ia.height; i++)
                if (memcmp(&ia.data[i], &ib.data[i], sizeof(float)) != 0)
                    fail_msg("part %d channel %s pixel %d: %g, the input has %g", p, cl->entries[k].name.str, i,
                             ib.data[i], ia.data[i]);
            obs_image_free(&ia);
            obs_image_free(&ib);
        }
    }
    exr_finish(&c);
    obs_strv_free(names);
}

static void test_append_parts(void **state)
{
    (void)state;
    const char *in = tmp_path("multi.exr"), *out = tmp_path("multiapp.exr");
    in_part parts[2] = {
        {.name = "beauty", .storage = EXR_STORAGE_TILED, .x0 = -3, .y0 = 2, .w = 21, .h = 13,
         .dx0 = 0, .dy0 = 0, .dx1 = 31, .dy1 = 23, .comp = EXR_COMPRESSION_PIZ, .nch = 3, .ch = {"R", "G", "B"},
         .type = {EXR_PIXEL_HALF, EXR_PIXEL_HALF, EXR_PIXEL_HALF}},
        {.name = "gbuffer", .storage = EXR_STORAGE_SCANLINE, .x0 = 1, .y0 = 1, .w = 20, .h = 18,
         .dx0 = 0, .dy0 = 0, .dx1 = 31, .dy1 = 23, .comp = EXR_COMPRESSION_PXR24, .nch = 4,
         .ch = {"Z", "N.X", "id", "mask"}, .type = {EXR_PIXEL_FLOAT, EXR_PIXEL_HALF, EXR_PIXEL_UINT, EXR_PIXEL_FLOAT}}};
    write_input(in, parts, 2, 1);
    obs_image img = {20, 18, 1, ao_pixels(20, 18)};
    const char *names[] = {"occ.Y"};
    obs_exr_layer l = {&img, names};
    obs_exr_source src = {.path = in, .part = 1};
    obs_exr_options o = {.pixel = OBS_EXR_FLOAT, .src = &src, .append = 1};
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_write_ex(out, &l, 1, &o, err) != OBS_OK)
        fail_msg("%s", err);
    check_unchanged(in, out);

    /* from the input in memory (the daemon's way): the same bytes */
    same_from_memory(in, out, &l, &o);

    exr_context_t a = open_exr(in), b = open_exr(out);
    static const char *const layout[] = {"channels", "compression", "dataWindow", "displayWindow",
                                         "lineOrder", "tiles", "chunkCount", "type", NULL};
    const char *name;
    exr_storage_t st;
    exr_compression_t comp;
    for (int p = 0; p < 2; p++) {
        check_attrs(b, a, p, p, layout); /* multiView too, in the input's own file */
        assert_int_equal(exr_get_name(b, p, &name), 0);
        assert_string_equal(name, parts[p].name);
        assert_int_equal(exr_get_storage(b, p, &st), 0);
        assert_int_equal(st, EXR_STORAGE_SCANLINE);
    }
    assert_int_equal(exr_get_compression(b, 0, &comp), 0);
    assert_int_equal(comp, EXR_COMPRESSION_PIZ); /* lossless: kept */
    assert_int_equal(exr_get_compression(b, 1, &comp), 0);
    assert_int_equal(comp, EXR_COMPRESSION_ZIP); /* PXR24 is lossy: ZIP */
    exr_finish(&a);
    exr_finish(&b);
    obs_image ao;
    if (obs_exr_read_channel(out, "occ.Y", NULL, &ao, err) != OBS_OK)
        fail_msg("%s", err);
    assert_memory_equal(ao.data, img.data, sizeof(float) * 20 * 18);
    obs_image_free(&ao);
    free(img.data);
}

static void test_append_refusals(void **state)
{
    (void)state;
    const char *in = tmp_path("app.exr"), *out = tmp_path("appout.exr"), *deep = tmp_path("deepin.exr");
    write_input(in, &cropped, 1, 0);
    remove(out);
    obs_image img = {10, 8, 1, ao_pixels(10, 8)};
    const char *dup[] = {"N.X"};
    obs_exr_layer l = {&img, dup};
    obs_exr_source src = {.path = in, .part = 0};
    obs_exr_options o = {.src = &src, .append = 1};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_exr_write_ex(out, &l, 1, &o, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "already has a channel 'N.X'"));
    assert_false(obs_test_exists(out));

    obs_exr_options nosrc = {.append = 1};
    assert_int_equal(obs_exr_write_ex(out, &l, 1, &nosrc, err), OBS_INVALID_ARGUMENT);
    obs_exr_source nopart = {.path = in, .part = 3};
    obs_exr_options bad = {.src = &nopart};
    assert_int_equal(obs_exr_write_ex(out, &l, 1, &bad, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "no part 3"));

    in_part d = {.storage = EXR_STORAGE_DEEP_SCANLINE, .x0 = 0, .y0 = 0, .w = 10, .h = 8,
                 .dx0 = 0, .dy0 = 0, .dx1 = 9, .dy1 = 7, .comp = EXR_COMPRESSION_NONE, .nch = 1, .ch = {"Z"},
                 .type = {EXR_PIXEL_FLOAT}};
    write_input(deep, &d, 1, 0);
    const char *ok[] = {"AO.Y"};
    obs_exr_layer lo = {&img, ok};
    obs_exr_source dsrc = {.path = deep, .part = 0};
    obs_exr_options dopt = {.src = &dsrc, .append = 1};
    assert_int_equal(obs_exr_write_ex(out, &lo, 1, &dopt, err), OBS_UNSUPPORTED);
    assert_non_null(strstr(err, "deep"));
    /* without append, a deep input still gives its windows and header */
    obs_exr_options dplain = {.src = &dsrc};
    if (obs_exr_write_ex(out, &lo, 1, &dplain, err) != OBS_OK)
        fail_msg("%s", err);
    free(img.data);
}

/* ---- provenance --------------------------------------------------------- */

static const char *str_attr(exr_context_t ctx, int part, const char *name)
{
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_name(ctx, part, name, &a) != EXR_ERR_SUCCESS || !a)
        return NULL;
    assert_int_equal(a->type, EXR_ATTR_STRING);
    return a->string->str;
}

/* obscura/version, method, params (what differs from the defaults),
 * input and camera_source on the AO's part, beside the input's own
 * attributes (its chromaticities, its renderer's keys); a rerun over
 * obscura's own output replaces the keys, in plain and append mode. */
static void test_provenance(void **state)
{
    (void)state;
    const char *in = tmp_path("prov_in.exr"), *out = tmp_path("prov.exr"), *again = tmp_path("prov2.exr");
    write_input(in, &cropped, 1, 1);
    obs_image img = {10, 8, 1, ao_pixels(10, 8)};
    const char *names[] = {"AO.Y"};
    obs_exr_layer l = {&img, names};
    char err[OBS_ERR_LEN] = "";
    obs_params p = {0};
    assert_int_equal(obs_param_set(&p, "method", "hbao", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "hbao_steps", "8", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "fov_y", "50", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "radius", "0.5", err), OBS_OK); /* the default: not listed */
    obs_provenance prov = {.params = &p, .input = in, .camera_source = "header worldToCamera"};
    obs_exr_source src = {.path = in, .part = 0};
    obs_exr_options o = {.src = &src, .prov = &prov};
    if (obs_exr_write_ex(out, &l, 1, &o, err) != OBS_OK)
        fail_msg("%s", err);
    exr_context_t b = open_exr(out);
    assert_string_equal(str_attr(b, 0, "obscura/version"), OBS_VERSION);
    assert_string_equal(str_attr(b, 0, "obscura/method"), "hbao");
    assert_string_equal(str_attr(b, 0, "obscura/params"), "method=hbao fov_y=50 hbao_steps=8");
    exr_finish(&b);
    /* a selector with spaces and quotes: in double quotes, escaped */
    assert_int_equal(obs_param_set(&p, "receivers", "name containing a \"quote\",b\\,c", err), OBS_OK);
    if (obs_exr_write_ex(out, &l, 1, &o, err) != OBS_OK)
        fail_msg("%s", err);
    b = open_exr(out);
    assert_string_equal(str_attr(b, 0, "obscura/params"),
                        "method=hbao fov_y=50 hbao_steps=8 "
                        "receivers=\"name containing a \\\"quote\\\",b\\\\,c\"");
    exr_finish(&b);
    assert_int_equal(obs_param_set(&p, "receivers", "", err), OBS_OK);
    if (obs_exr_write_ex(out, &l, 1, &o, err) != OBS_OK) /* as before, for what follows */
        fail_msg("%s", err);
    b = open_exr(out);
    assert_string_equal(str_attr(b, 0, "obscura/input"), in);
    assert_string_equal(str_attr(b, 0, "obscura/camera_source"), "header worldToCamera");
    assert_string_equal(str_attr(b, 0, "arnold/version"), "7.1.4");
    const exr_attribute_t *chr = NULL;
    assert_int_equal(exr_get_attribute_by_name(b, 0, "chromaticities", &chr), 0);
    assert_int_equal(chr->type, EXR_ATTR_CHROMATICITIES);
    assert_true(chr->chromaticities->red_x == 0.64f && chr->chromaticities->white_y == 0.329f);
    exr_finish(&b);
    same_from_memory(in, out, &l, &o);

    /* obscura over its own output: the keys are this run's alone */
    obs_params defaults = {0};
    obs_provenance prov2 = {.params = &defaults, .input = out};
    obs_exr_source src2 = {.path = out, .part = 0};
    const char *n2[] = {"AO2.Y"};
    obs_exr_layer l2 = {&img, n2};
    for (int append = 0; append <= 1; append++) {
        obs_exr_options o2 = {.src = &src2, .prov = &prov2, .append = append};
        if (obs_exr_write_ex(again, &l2, 1, &o2, err) != OBS_OK)
            fail_msg("%s", err);
        b = open_exr(again);
        assert_string_equal(str_attr(b, 0, "obscura/method"), "vaopp");
        assert_string_equal(str_attr(b, 0, "obscura/params"), "");
        assert_string_equal(str_attr(b, 0, "obscura/input"), out);
        /* not given this time: the earlier run's is not kept beside this run's keys */
        assert_null(str_attr(b, 0, "obscura/camera_source"));
        assert_string_equal(str_attr(b, 0, "arnold/version"), "7.1.4");
        exr_finish(&b);
    }

    /* zeroed options: obscura/version alone */
    obs_exr_options plain = {0};
    if (obs_exr_write_ex(again, &l, 1, &plain, err) != OBS_OK)
        fail_msg("%s", err);
    b = open_exr(again);
    assert_string_equal(str_attr(b, 0, "obscura/version"), OBS_VERSION);
    assert_null(str_attr(b, 0, "obscura/method"));
    assert_null(str_attr(b, 0, "obscura/input"));
    exr_finish(&b);
    free(img.data);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_windows_from_options),
        cmocka_unit_test(test_source_header),
        cmocka_unit_test(test_layer_names),
        cmocka_unit_test(test_append_parts),
        cmocka_unit_test(test_append_refusals),
        cmocka_unit_test(test_provenance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
