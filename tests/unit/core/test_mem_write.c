/* In-memory encoders: obs_exr_write_mem and obs_png_write_mem give the
 * same bytes as the file writers, and fail the same way. */
#include "testutil.h"

#include "obscura/io.h"

#define W 61
#define H 29

static obs_image make_image(int channels)
{
    obs_image img = {W, H, channels, malloc(sizeof(float) * W * H * (size_t)channels)};
    for (int i = 0; i < W * H * channels; i++)
        img.data[i] = (float)(i % 97) / 80.0f - 0.1f;
    return img;
}

static void assert_same_bytes(const char *path, const obs_bytes *mem)
{
    size_t n;
    unsigned char *file = obs_test_slurp(path, &n);
    assert_int_equal(mem->size, n);
    assert_memory_equal(mem->data, file, n);
    free(file);
}

static void exr_case(obs_exr_pixel pixel, int with_camera)
{
    obs_image ao = make_image(1), comp = make_image(4);
    static const char *const ao_names[] = {"AO.Y"};
    static const char *const rgba[] = {"R", "G", "B", "A"};
    obs_exr_layer layers[] = {{&ao, ao_names}, {&comp, rgba}};
    obs_camera cam = {0};
    obs_camera_from_fov(50.0f, (float)W / H, 0.1f, 100.0f, &cam);
    cam.has_world_to_camera = 1;
    char path[512], err[OBS_ERR_LEN] = "";
    snprintf(path, sizeof path, "%s/mem_%d_%d.exr", obs_test_tmp(), (int)pixel, with_camera);
    if (obs_exr_write(path, layers, 2, pixel, with_camera ? &cam : NULL, err) != OBS_OK)
        fail_msg("%s", err);
    obs_bytes mem = {0};
    if (obs_exr_write_mem(layers, 2, pixel, with_camera ? &cam : NULL, &mem, err) != OBS_OK)
        fail_msg("%s", err);
    assert_same_bytes(path, &mem);
    /* and the reader takes it back from memory */
    obs_gbuffer_file gf = {0};
    obs_channel_map map = {.depth = "AO.Y"};
    if (obs_gbuffer_read_exr_mem(mem.data, mem.size, &map, NULL, &gf, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(gf.gb.width, W);
    assert_int_equal(gf.gb.height, H);
    obs_gbuffer_free(&gf);
    obs_bytes_free(&mem);
    assert_null(mem.data);
    obs_image_free(&ao);
    obs_image_free(&comp);
}

static void test_exr_half(void **state)
{
    (void)state;
    exr_case(OBS_EXR_HALF, 0);
}

static void test_exr_float_camera(void **state)
{
    (void)state;
    exr_case(OBS_EXR_FLOAT, 1);
}

static void png_case(int channels, int bits, int srgb)
{
    obs_image img = make_image(channels);
    char path[512], err[OBS_ERR_LEN] = "";
    snprintf(path, sizeof path, "%s/mem_%d_%d_%d.png", obs_test_tmp(), channels, bits, srgb);
    if (obs_png_write(path, &img, bits, srgb, err) != OBS_OK)
        fail_msg("%s", err);
    obs_bytes mem = {0};
    if (obs_png_write_mem(&img, bits, srgb, &mem, err) != OBS_OK)
        fail_msg("%s", err);
    assert_same_bytes(path, &mem);
    assert_memory_equal(mem.data, "\x89PNG", 4);
    obs_bytes_free(&mem);
    obs_image_free(&img);
}

static void test_png(void **state)
{
    (void)state;
    png_case(1, 8, 0);
    png_case(1, 16, 0);
    png_case(3, 8, 1);
    png_case(4, 16, 1);
}

static void test_errors(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bytes mem = {(unsigned char *)1, 7}; /* overwritten on entry */
    obs_image img = make_image(2);
    assert_int_equal(obs_png_write_mem(&img, 8, 0, &mem, err), OBS_INVALID_ARGUMENT);
    assert_null(mem.data);
    assert_non_null(strstr(err, "channels"));
    assert_int_equal(obs_png_write_mem(&img, 8, 0, NULL, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_exr_write_mem(NULL, 0, OBS_EXR_HALF, NULL, &mem, err), OBS_INVALID_ARGUMENT);
    assert_null(mem.data);
    obs_bytes_free(NULL);
    obs_image_free(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exr_half),
        cmocka_unit_test(test_exr_float_camera),
        cmocka_unit_test(test_png),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests_name("mem_write", tests, NULL, NULL);
}
