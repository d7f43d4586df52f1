/* Camera JSON and field-of-view cameras. */
#include "testutil.h"

#include <math.h>

#include "obscura/io.h"

static const char *write_tmp(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", obs_test_tmp(), name);
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
    return path;
}

static void test_room_small(void **state)
{
    (void)state;
    obs_camera cam;
    int w = -1, h = -1;
    char err[OBS_ERR_LEN] = "";
    if (obs_camera_read_json(TESTDATA "/room_small.camera.json", &cam, &w, &h, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(w, 320);
    assert_int_equal(h, 240);
    assert_int_equal(cam.source, OBS_CAMERA_JSON);
    assert_int_equal(cam.has_world_to_camera, 1);
    assert_int_equal(cam.has_projection, 1);
    assert_float_equal(cam.projection[0], 1.6083802, 1e-6);
    assert_float_equal(cam.projection[5], 2.1445069, 1e-6);
    assert_float_equal(cam.projection[10], -1.0010005, 1e-6);
    assert_float_equal(cam.projection[11], -0.10005002, 1e-7);
    assert_float_equal(cam.projection[14], -1.0, 0.0);
    assert_float_equal(cam.world_to_camera[0], 0.79128504, 1e-7);
    assert_float_equal(cam.world_to_camera[3], -0.10070872, 1e-7);
    assert_float_equal(cam.world_to_camera[11], -4.3877349, 1e-6);
    assert_float_equal(cam.world_to_camera[15], 1.0, 0.0);

    /* the projection is the one a 50-degree field of view gives */
    obs_camera fov;
    obs_camera_from_fov(50.0f, 320.0f / 240.0f, 0.05f, 100.0f, &fov);
    for (int i = 0; i < 16; i++)
        assert_float_equal(cam.projection[i], fov.projection[i], 1e-5);
    /* width/height may be NULL */
    assert_int_equal(obs_camera_read_json(TESTDATA "/yard_small.camera.json", &cam, NULL, NULL, err), OBS_OK);
}

static void test_from_fov(void **state)
{
    (void)state;
    obs_camera cam;
    obs_camera_from_fov(90.0f, 2.0f, 1.0f, 3.0f, &cam);
    const float want[16] = {0.5f, 0, 0, 0, 0, 1, 0, 0, 0, 0, -2.0f, -3.0f, 0, 0, -1, 0};
    const float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (int i = 0; i < 16; i++) {
        assert_float_equal(cam.projection[i], want[i], 1e-6);
        assert_float_equal(cam.world_to_camera[i], id[i], 0.0);
    }
    assert_int_equal(cam.has_projection, 1);
    assert_int_equal(cam.has_world_to_camera, 0);
    assert_int_equal(cam.source, OBS_CAMERA_PARAMS);

    obs_camera_from_fov(50.0f, 4.0f / 3.0f, 0.1f, 1000.0f, &cam);
    double f = 1.0 / tan(25.0 * 3.14159265358979323846 / 180.0);
    assert_float_equal(cam.projection[5], f, 1e-6);
    assert_float_equal(cam.projection[0], f * 0.75, 1e-6);
    assert_float_equal(cam.projection[10], -1000.1 / 999.9, 1e-6);
    assert_float_equal(cam.projection[11], -200.0 / 999.9, 1e-6);
}

#define WTC "\"world_to_camera\": [[1,0,0,0],[0,1,0,0],[0,0,1,-5],[0,0,0,1]]"
#define PROJ "\"projection\": [[1,0,0,0],[0,1,0,0],[0,0,-1,-0.2],[0,0,-1,0]]"

/* Each malformed file fails with BAD_FILE and a message naming `field`. */
static void expect_bad(const char *json, const char *field)
{
    obs_camera cam;
    memset(&cam, 0x5a, sizeof cam);
    obs_camera before = cam;
    char err[OBS_ERR_LEN] = "";
    const char *path = write_tmp("bad.camera.json", json);
    obs_status st = obs_camera_read_json(path, &cam, NULL, NULL, err);
    if (st != OBS_BAD_FILE || !strstr(err, field))
        fail_msg("%s: got %s '%s', expected BAD_FILE naming %s", json, obs_status_name(st), err, field);
    assert_memory_equal(&cam, &before, sizeof cam); /* untouched on failure */
}

static void test_malformed(void **state)
{
    (void)state;
    expect_bad("{" PROJ "}", "world_to_camera: missing");
    expect_bad("{" WTC "}", "projection: missing");
    expect_bad("{\"fov_y_deg\": \"fifty\", " WTC ", " PROJ "}", "fov_y_deg: expected a number");
    expect_bad("{\"width\": 320.5, " WTC ", " PROJ "}", "width");
    expect_bad("{\"height\": -2, " WTC ", " PROJ "}", "height");
    expect_bad("{\"near\": 0, " WTC ", " PROJ "}", "near");
    expect_bad("{\"near\": 2, \"far\": 1, " WTC ", " PROJ "}", "far");
    expect_bad("{\"fov_y_deg\": 190, " WTC ", " PROJ "}", "fov_y_deg");
    expect_bad("{\"world_to_camera\": [[1,0,0],[0,1,0],[0,0,1]], " PROJ "}", "world_to_camera: expected 4 rows");
    expect_bad("{\"world_to_camera\": \"identity\", " PROJ "}", "world_to_camera");
    expect_bad("{" WTC ", \"projection\": [[1,0,0,0],[0,1,0,0],[0,0,-1,\"x\"],[0,0,-1,0]]}", "projection");
    expect_bad("{\"world_to_camera\": [[0,0,0,0],[0,0,0,0],[0,0,0,0],[0,0,0,1]], " PROJ "}",
               "world_to_camera: the matrix is singular");
    expect_bad("{\"width\": 320, " WTC ", \"fov_y_deg\": 50}", "projection");
    expect_bad("{\"width\": 320, " WTC,  "not valid JSON");
    expect_bad("this is not JSON", "not valid JSON");
    expect_bad("[1, 2, 3]", "not a JSON object");
    expect_bad("", "not valid JSON");
    /* numbers a double holds and a float does not: an infinity in the
     * camera's matrices, a zero near plane, a far plane on the near one */
    expect_bad("{\"world_to_camera\": [1e39,0,0,0, 0,1,0,0, 0,0,1,-5, 0,0,0,1], " PROJ "}",
               "world_to_camera");
    expect_bad("{" WTC ", \"projection\": [[1,0,0,0],[0,1,0,0],[0,0,-1,-1e300],[0,0,-1,0]]}",
               "projection");
    expect_bad("{\"near\": 1e-50, \"width\": 320, \"height\": 240, \"fov_y_deg\": 50, " WTC "}",
               "near");
    expect_bad("{\"near\": 1, \"far\": 1.00000001, \"width\": 320, \"height\": 240, "
               "\"fov_y_deg\": 50, " WTC "}", "far");
    expect_bad("{\"far\": 1e39, \"width\": 320, \"height\": 240, \"fov_y_deg\": 50, " WTC "}",
               "far");
}

static void test_fov_only_and_flat(void **state)
{
    (void)state;
    obs_camera cam;
    int w = 0, h = 0;
    char err[OBS_ERR_LEN] = "";
    const char *path = write_tmp("fov.camera.json",
                                 "{\"width\": 200, \"height\": 100, \"fov_y_deg\": 90, \"near\": 1, \"far\": 3,"
                                 " \"world_to_camera\": [1,0,0,0, 0,1,0,0, 0,0,1,-5, 0,0,0,1]}");
    if (obs_camera_read_json(path, &cam, &w, &h, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(w, 200);
    assert_int_equal(h, 100);
    assert_int_equal(cam.source, OBS_CAMERA_JSON);
    assert_int_equal(cam.has_world_to_camera, 1);
    assert_float_equal(cam.world_to_camera[11], -5.0, 0.0); /* flat 16 numbers, row-major */
    assert_float_equal(cam.projection[0], 0.5, 1e-6);
    assert_float_equal(cam.projection[5], 1.0, 1e-6);
    assert_float_equal(cam.projection[10], -2.0, 1e-6);

    /* without width and height, *width and *height are 0 */
    path = write_tmp("noimage.camera.json", "{" WTC ", " PROJ "}");
    w = h = -1;
    assert_int_equal(obs_camera_read_json(path, &cam, &w, &h, err), OBS_OK);
    assert_int_equal(w, 0);
    assert_int_equal(h, 0);
}

static void test_io_errors(void **state)
{
    (void)state;
    obs_camera cam;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_camera_read_json(TESTDATA "/no_such.camera.json", &cam, NULL, NULL, err), OBS_IO);
    assert_non_null(strstr(err, "no_such.camera.json"));
    /* a large file is refused before it is parsed */
    char path[512];
    snprintf(path, sizeof path, "%s/big.camera.json", obs_test_tmp());
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    for (int i = 0; i < (1 << 20) / 8 + 1; i++)
        fputs("        ", fp);
    fclose(fp);
    assert_int_equal(obs_camera_read_json(path, &cam, NULL, NULL, err), OBS_TOO_LARGE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_room_small),
        cmocka_unit_test(test_from_fov),
        cmocka_unit_test(test_malformed),
        cmocka_unit_test(test_fov_only_and_flat),
        cmocka_unit_test(test_io_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
