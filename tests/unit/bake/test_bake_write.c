/* The bake's outputs are written whole or not at all (io/out_file.h): a
 * finished .glb or .ply leaves no temporary beside it, and a write that
 * fails half way (the file size limit, as a full disk) leaves neither the
 * file nor its temporary. */
#include <stdlib.h>
#include <unistd.h>

#include "level/bake_testutil.h"

static void test_whole_or_nothing(void **state)
{
    (void)state;
    obs_bake_mesh m;
    const float o[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
    bt_grid(&m, "plane", o, u, v, 4, 4);
    obs_bake_scene s;
    bt_scene(&s, &m, 1);
    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "16");
    obs_bake_result r;
    char err[OBS_ERR_LEN] = "", dir[] = "/tmp/obs_write_XXXXXX", path[64], list[256];
    assert_int_equal(obs_bake_run(&s, &d, &r, err), OBS_OK);
    assert_non_null(mkdtemp(dir));

    snprintf(path, sizeof path, "%s/a.glb", dir);
    assert_int_equal(obs_bake_write_glb(path, &s, &r, 1, err), OBS_OK);
    snprintf(path, sizeof path, "%s/a.ply", dir);
    assert_int_equal(obs_bake_write_ply(path, &s, &r, err), OBS_OK);
    bt_dir_list(dir, list, sizeof list);
    assert_string_equal(list, "a.glb/a.ply/");

    /* both files are far longer than 100 bytes: each write fails after
     * its first bytes reached the temporary */
    bt_file_limit(100);
    snprintf(path, sizeof path, "%s/b.glb", dir);
    obs_status gst = obs_bake_write_glb(path, &s, &r, 1, err);
    snprintf(path, sizeof path, "%s/b.ply", dir);
    obs_status pst = obs_bake_write_ply(path, &s, &r, err);
    /* an existing file is not replaced by a failed write */
    snprintf(path, sizeof path, "%s/a.glb", dir);
    obs_status rst = obs_bake_write_glb(path, &s, &r, 0, err);
    bt_file_limit(0);
    assert_int_equal(gst, OBS_IO);
    assert_int_equal(pst, OBS_IO);
    assert_int_equal(rst, OBS_IO);
    bt_dir_list(dir, list, sizeof list);
    assert_string_equal(list, "a.glb/a.ply/");
    obs_bake_scene back;
    assert_int_equal(obs_bake_load(path, 0, &back, err), OBS_OK);
    obs_bake_scene_free(&back);

    snprintf(path, sizeof path, "%s/a.glb", dir);
    remove(path);
    snprintf(path, sizeof path, "%s/a.ply", dir);
    remove(path);
    rmdir(dir);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_whole_or_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
