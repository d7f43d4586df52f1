/* PNG output, read back with libpng: bit depths, channel layouts,
 * clamping, the sRGB curve on colour only, and errors. */
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
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_libpng_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
