/* PNG output, read back with libpng: bit depths, channel layouts,
 * clamping, the transfer (sRGB or linear) and its tags, display colour
 * over 1, the provenance text chunks, and errors. */
#include "testutil.h"

#include <math.h>
#include <png.h>

#include "obscura/io.h"

static const char *tmp_path(const char *name)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", obs_test_tmp(), name);
    return path;
}

typedef struct png_read {
    unsigned w, h;
    int bits, type;
    int has_srgb;
    double gamma; /* the gAMA chunk's (0: none) */
    int ntext;
    char text[8][2][512]; /* key, value of each text chunk */
    int itxt[8];          /* 1: that chunk is iTXt */
    unsigned char *pix; /* rows packed, samples as stored (big-endian) */
    size_t rowbytes;
} png_read;

static void read_png(const char *path, png_read *r)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    assert_non_null(info);
    if (setjmp(png_jmpbuf(png)))
        fail_msg("libpng could not read %s", path);
    png_init_io(png, fp);
    png_read_png(png, info, PNG_TRANSFORM_IDENTITY, NULL);
    r->w = png_get_image_width(png, info);
    r->h = png_get_image_height(png, info);
    r->bits = png_get_bit_depth(png, info);
    r->type = png_get_color_type(png, info);
    r->has_srgb = png_get_valid(png, info, PNG_INFO_sRGB) != 0;
    r->gamma = 0.0;
    png_get_gAMA(png, info, &r->gamma);
    png_textp text = NULL;
    r->ntext = png_get_text(png, info, &text, NULL);
    for (int i = 0; i < r->ntext && i < 8; i++) {
        snprintf(r->text[i][0], sizeof r->text[i][0], "%s", text[i].key);
        snprintf(r->text[i][1], sizeof r->text[i][1], "%s", text[i].text);
        r->itxt[i] = text[i].compression == PNG_ITXT_COMPRESSION_NONE;
    }
    r->rowbytes = png_get_rowbytes(png, info);
    r->pix = malloc(r->rowbytes * r->h);
    png_bytepp rows = png_get_rows(png, info);
    for (unsigned y = 0; y < r->h; y++)
        memcpy(r->pix + y * r->rowbytes, rows[y], r->rowbytes);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(fp);
}

static unsigned sample(const png_read *r, unsigned x, unsigned y, int ch, int channels)
{
    const unsigned char *p = r->pix + y * r->rowbytes;
    size_t i = (size_t)x * channels + ch;
    return r->bits == 16 ? (unsigned)p[2 * i] << 8 | p[2 * i + 1] : p[i];
}

static double srgb(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static void test_grey_8(void **state)
{
    (void)state;
    float px[6] = {0.0f, 0.5f, 1.0f, -0.5f, 1.5f, NAN};
    obs_image img = {3, 2, 1, px};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("grey8.png");
    /* srgb does not touch grey (AO stays linear) */
    assert_int_equal(obs_png_write(path, &img, 8, 1, err), OBS_OK);
    png_read r;
    read_png(path, &r);
    assert_int_equal(r.w, 3);
    assert_int_equal(r.h, 2);
    assert_int_equal(r.bits, 8);
    assert_int_equal(r.type, PNG_COLOR_TYPE_GRAY);
    static const unsigned want[6] = {0, 128, 255, 0, 255, 0};
    for (int i = 0; i < 6; i++)
        assert_int_equal(sample(&r, i % 3, i / 3, 0, 1), want[i]);
    free(r.pix);
}

static void test_rgb_16(void **state)
{
    (void)state;
    enum { w = 64, h = 5 };
    static float px[w * h * 3];
    for (int i = 0; i < w * h * 3; i++)
        px[i] = (float)i / (w * h * 3 - 1);
    obs_image img = {w, h, 3, px};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("rgb16.png");
    assert_int_equal(obs_png_write(path, &img, 16, 0, err), OBS_OK);
    png_read r;
    read_png(path, &r);
    assert_int_equal(r.bits, 16);
    assert_int_equal(r.type, PNG_COLOR_TYPE_RGB);
    assert_false(r.has_srgb);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                unsigned want = (unsigned)lrint(px[(y * w + x) * 3 + c] * 65535.0);
                assert_int_equal(sample(&r, x, y, c, 3), want);
            }
    free(r.pix);
}

static void test_rgba_srgb(void **state)
{
    (void)state;
    float px[8] = {0.5f, 0.2f, 0.001f, 0.5f, 1.0f, 0.0f, 0.25f, 0.75f};
    obs_image img = {2, 1, 4, px};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("rgba.png");
    for (int bits = 8; bits <= 16; bits += 8) {
        assert_int_equal(obs_png_write(path, &img, bits, 1, err), OBS_OK);
        png_read r;
        read_png(path, &r);
        assert_int_equal(r.type, PNG_COLOR_TYPE_RGB_ALPHA);
        assert_true(r.has_srgb);
        double max = bits == 16 ? 65535.0 : 255.0;
        for (int i = 0; i < 8; i++) {
            double v = i % 4 == 3 ? px[i] : srgb(px[i]); /* alpha stays linear */
            assert_int_equal(sample(&r, i / 4, 0, i % 4, 4), (unsigned)lrint(v * max));
        }
        /* the sRGB curve lifts mid grey: 0.5 -> about 188/255 */
        if (bits == 8)
            assert_int_equal(sample(&r, 0, 0, 0, 4), 188);
        free(r.pix);
    }
}

/* The value of text chunk `key`, NULL when absent. */
static const char *text_of(const png_read *r, const char *key, int *itxt)
{
    for (int i = 0; i < r->ntext && i < 8; i++)
        if (!strcmp(r->text[i][0], key)) {
            if (itxt)
                *itxt = r->itxt[i];
            return r->text[i][1];
        }
    return NULL;
}

/* The 4 bytes of the file's cICP chunk, or NULL (libpng 1.6 does not
 * parse it: found in the bytes, its length 4 before the name). */
static const unsigned char *cicp_of(const unsigned char *file, size_t len)
{
    for (size_t i = 12; i + 8 <= len; i++)
        if (!memcmp(file + i, "cICP", 4) && !memcmp(file + i - 4, "\0\0\0\4", 4))
            return file + i + 4;
    return NULL;
}

/* The default transfer is sRGB (read right by Nuke's and OpenImageIO's
 * defaults): grey AO encoded, sRGB chunk.  Linear: the values as they
 * are, gAMA 1.0 and cICP (BT.709, linear, full range).  The older call
 * without srgb is linear, now tagged as such. */
static void test_transfer_tags(void **state)
{
    (void)state;
    float px[3] = {0.0f, 0.214f, 0.5f};
    obs_image img = {3, 1, 1, px};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("transfer.png");
    png_read r;
    size_t len;

    obs_png_options def = {0};
    assert_int_equal(obs_png_write_ex(path, &img, &def, err), OBS_OK);
    read_png(path, &r);
    assert_true(r.has_srgb);
    assert_int_equal(sample(&r, 1, 0, 0, 1), (unsigned)lrint(srgb(0.214) * 255.0)); /* 128 */
    assert_int_equal(sample(&r, 2, 0, 0, 1), 188);
    unsigned char *file = obs_test_slurp(path, &len);
    assert_null(cicp_of(file, len));
    free(file);
    free(r.pix);

    obs_png_options lin = {.bits = 16, .transfer = OBS_PNG_TRANSFER_LINEAR};
    for (int legacy = 0; legacy <= 1; legacy++) {
        if (legacy)
            assert_int_equal(obs_png_write(path, &img, 16, 0, err), OBS_OK);
        else
            assert_int_equal(obs_png_write_ex(path, &img, &lin, err), OBS_OK);
        read_png(path, &r);
        assert_false(r.has_srgb);
        assert_true(fabs(r.gamma - 1.0) < 1e-5);
        assert_int_equal(sample(&r, 2, 0, 0, 1), 32768);
        file = obs_test_slurp(path, &len);
        const unsigned char *c = cicp_of(file, len);
        assert_non_null(c);
        assert_memory_equal(c, "\1\10\0\1", 4);
        free(file);
        free(r.pix);
    }
    assert_int_equal(obs_png_transfer_parse("linear"), OBS_PNG_TRANSFER_LINEAR);
    assert_int_equal(obs_png_transfer_parse("srgb"), OBS_PNG_TRANSFER_SRGB);
    assert_int_equal(obs_png_transfer_parse("gamma"), OBS_PNG_TRANSFER_DEFAULT);
}

/* Display colour (a composite) over 1: scaled by its largest channel,
 * hue kept; every pixel at most 1 unchanged; sRGB-encoded and tagged
 * even under the linear transfer. */
static void test_display_hdr(void **state)
{
    (void)state;
    float px[16] = {4.0f, 1.0f, 0.5f, 1.0f,  0.5f, 0.2f, 0.1f, 0.5f,
                    INFINITY, 2.0f, NAN, 1.0f,  -1.0f, 1.0f, 0.25f, 1.0f};
    obs_image img = {4, 1, 4, px};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("hdr.png");
    obs_png_options o = {.transfer = OBS_PNG_TRANSFER_LINEAR, .display = 1};
    assert_int_equal(obs_png_write_ex(path, &img, &o, err), OBS_OK);
    png_read r;
    read_png(path, &r);
    assert_true(r.has_srgb);
    static const double want[16] = {1.0, 0.25, 0.125, 1.0,  0.5, 0.2, 0.1, 0.5,
                                    1.0, 0.0, 0.0, 1.0,  0.0, 1.0, 0.25, 1.0};
    for (int i = 0; i < 16; i++) {
        double v = i % 4 == 3 ? want[i] : srgb(want[i]);
        if (sample(&r, i / 4, 0, i % 4, 4) != (unsigned)lrint(v * 255.0))
            fail_msg("pixel %d channel %d: %u, want %ld", i / 4, i % 4, sample(&r, i / 4, 0, i % 4, 4),
                     lrint(v * 255.0));
    }
    free(r.pix);
}

/* obscura/version always; method, params, input, camera_source as given;
 * a non-ASCII value in iTXt; the memory writer the same bytes. */
static void test_provenance_text(void **state)
{
    (void)state;
    float px[4] = {0.25f, 0.5f, 0.75f, 1.0f};
    obs_image img = {2, 2, 1, px};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("prov.png");
    png_read r;
    int itxt = -1;

    assert_int_equal(obs_png_write(path, &img, 8, 0, err), OBS_OK);
    read_png(path, &r);
    assert_string_equal(text_of(&r, "obscura/version", NULL), OBS_VERSION);
    assert_null(text_of(&r, "obscura/method", NULL));
    free(r.pix);

    obs_params p = {0};
    assert_int_equal(obs_param_set(&p, "radius", "2", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "samples", "8", err), OBS_OK);
    obs_provenance prov = {.params = &p, .input = "shot/\xc3\xa9t\xc3\xa9.0001.exr", .camera_source = "camera JSON"};
    obs_png_options o = {.prov = &prov};
    assert_int_equal(obs_png_write_ex(path, &img, &o, err), OBS_OK);
    read_png(path, &r);
    assert_string_equal(text_of(&r, "obscura/version", &itxt), OBS_VERSION);
    assert_int_equal(itxt, 0);
    assert_string_equal(text_of(&r, "obscura/method", NULL), "vaopp");
    assert_string_equal(text_of(&r, "obscura/params", NULL), "radius=2 samples=8");
    assert_string_equal(text_of(&r, "obscura/input", &itxt), "shot/\xc3\xa9t\xc3\xa9.0001.exr");
    assert_int_equal(itxt, 1);
    assert_string_equal(text_of(&r, "obscura/camera_source", NULL), "camera JSON");
    free(r.pix);

    size_t len;
    unsigned char *file = obs_test_slurp(path, &len);
    obs_bytes mem;
    assert_int_equal(obs_png_write_ex_mem(&img, &o, &mem, err), OBS_OK);
    assert_int_equal(mem.size, len);
    assert_memory_equal(mem.data, file, len);
    obs_bytes_free(&mem);
    free(file);
}

static void test_errors(void **state)
{
    (void)state;
    float px[4] = {0};
    obs_image two = {1, 1, 2, px}, one = {1, 1, 1, px};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_png_write(tmp_path("x.png"), &two, 8, 0, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "channels"));
    assert_int_equal(obs_png_write(tmp_path("x.png"), &one, 12, 0, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "12"));
    assert_int_equal(obs_png_write(tmp_path("x.png"), NULL, 8, 0, err), OBS_INVALID_ARGUMENT);
    err[0] = '\0';
    assert_int_equal(obs_png_write("/nonexistent-dir/x.png", &one, 8, 0, err), OBS_IO);
    assert_non_null(strstr(err, "/nonexistent-dir/x.png"));
}

/* A libpng failure (here its width limit, checked in png_set_IHDR) comes
 * back as a status through setjmp, with libpng's message, and leaves no
 * file behind. */
static void test_libpng_error(void **state)
{
    (void)state;
    float px[1] = {0.5f}; /* libpng fails before reading any row */
    obs_image img = {PNG_USER_WIDTH_MAX + 1, 1, 1, px};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("too_wide.png");
    assert_int_equal(obs_png_write(path, &img, 8, 0, err), OBS_IO);
    assert_non_null(strstr(err, "width"));
    assert_false(obs_test_exists(path));
    print_message("libpng error: %s\n", err);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grey_8),
        cmocka_unit_test(test_rgb_16),
        cmocka_unit_test(test_rgba_srgb),
        cmocka_unit_test(test_transfer_tags),
        cmocka_unit_test(test_display_hdr),
        cmocka_unit_test(test_provenance_text),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_libpng_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
