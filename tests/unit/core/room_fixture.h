/* room_small (tests/data) with its camera, read once per test group:
 * `room`, and cmocka's group setup and teardown for it. */
#ifndef OBS_TEST_ROOM_FIXTURE_H
#define OBS_TEST_ROOM_FIXTURE_H

#include "testutil.h"
#include "obscura/io.h"

static obs_gbuffer_file room;

static int setup(void **state)
{
    char err[OBS_ERR_LEN] = "";
    (void)state;
    if (obs_gbuffer_read_exr(TESTDATA "/room_small.exr", NULL, NULL, &room, err) != OBS_OK ||
        obs_camera_read_json(TESTDATA "/room_small.camera.json", &room.gb.camera, NULL, NULL,
                             err) != OBS_OK)
        fail_msg("room_small: %s", err);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    obs_gbuffer_free(&room);
    return 0;
}

#endif
