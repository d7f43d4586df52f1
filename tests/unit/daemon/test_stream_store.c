/* The stream store of the preview page (daemon/stream_store.c): bounded
 * frames and streams, references outliving a drop, subscribers parked,
 * woken and told the end; the JSON of deep frames, params and cameras. */
#include <math.h>

#include "testutil.h"

#include "stream_store.h"

/* A frame of w x h whose AO plane holds `fill`. */
static obsd_frame *frame(int w, int h, float fill)
{
    obsd_frame *f = obsd_frame_new();
    assert_non_null(f);
    f->width = w;
    f->height = h;
    f->ao = (obs_image){w, h, 1, malloc((size_t)w * h * sizeof(float))};
    for (int i = 0; i < w * h; i++)
        f->ao.data[i] = fill;
    return f;
}

static void test_frames_bounded(void **state)
{
    (void)state;
    obsd_streams *s = obsd_streams_new(4, 3, 1 << 30);
    for (int i = 1; i <= 5; i++)
        assert_int_equal(obsd_streams_add(s, "shot", frame(4, 4, (float)i)), i);
    int found = 0;
    assert_null(obsd_streams_get(s, "shot", 2, &found)); /* 1 and 2 dropped */
    assert_true(found);
    obsd_frame *f = obsd_streams_get(s, "shot", 3, NULL);
    assert_non_null(f);
    assert_float_equal(f->ao.data[0], 3.0f, 0);
    obsd_frame_release(f);
    f = obsd_streams_get(s, "shot", 0, NULL); /* the newest */
    assert_int_equal(f->seq, 5);
    obsd_frame_release(f);
    assert_null(obsd_streams_get(s, "nobody", 0, &found));
    assert_false(found);
    obsd_streams_free(s);
}

static void test_bytes_bounded(void **state)
{
    (void)state;
    /* room for about two 64x64 AO planes (16 KiB each) */
    obsd_streams *s = obsd_streams_new(4, 100, 40000);
    for (int i = 0; i < 6; i++)
        obsd_streams_add(s, "a", frame(64, 64, 0.5f));
    int ns, nf, subs;
    uint64_t bytes;
    obsd_streams_gauges(s, &ns, &nf, &bytes, &subs);
    assert_int_equal(ns, 1);
    assert_int_equal(nf, 2);
    assert_true(bytes <= 40000);
    /* one frame over the limit on its own: still kept, alone */
    obsd_streams_add(s, "a", frame(128, 128, 0.5f));
    obsd_streams_gauges(s, &ns, &nf, &bytes, &subs);
    assert_int_equal(nf, 1);
    obsd_streams_free(s);
}

static int parked, woken;
static void on_park(void *arg) { (void)arg; parked++; }
static void on_wake(void *arg) { (void)arg; woken++; }

static void test_streams_bounded_and_refs(void **state)
{
    (void)state;
    obsd_streams *s = obsd_streams_new(2, 4, 1 << 30);
    obsd_streams_add(s, "a", frame(2, 2, 1));
    obsd_streams_add(s, "b", frame(2, 2, 2));
    obsd_streams_add(s, "a", frame(2, 2, 3)); /* b is now the least recently posted-to */
    obsd_frame *kept = obsd_streams_get(s, "b", 1, NULL);
    obsd_sub sub = {.park = on_park, .wake = on_wake};
    assert_int_equal(obsd_streams_subscribe(s, "b", &sub, 0), 0);
    /* a subscriber makes no room: an unknown stream is refused when full */
    obsd_sub other = {.park = on_park, .wake = on_wake};
    assert_int_equal(obsd_streams_subscribe(s, "zzz", &other, 0), -1);
    char buf[512];
    parked = woken = 0;
    assert_true(obsd_streams_next_event(s, &sub, buf, sizeof buf, 0) > 0); /* b's frame 1 */
    assert_non_null(strstr(buf, "\"frame\":1"));
    assert_int_equal(obsd_streams_next_event(s, &sub, buf, sizeof buf, 0), 0);
    assert_int_equal(parked, 1);
    obsd_streams_add(s, "c", frame(2, 2, 4)); /* drops b */
    assert_int_equal(woken, 1);
    int found = 1;
    assert_null(obsd_streams_get(s, "b", 0, &found));
    assert_false(found);
    assert_float_equal(kept->ao.data[0], 2.0f, 0); /* still ours */
    obsd_frame_release(kept);
    assert_true(obsd_streams_next_event(s, &sub, buf, sizeof buf, 0) > 0);
    assert_non_null(strstr(buf, "event: end"));
    assert_int_equal(obsd_streams_next_event(s, &sub, buf, sizeof buf, 0), -1);
    obsd_streams_unsubscribe(s, &sub); /* frees the dropped stream */
    obsd_streams_free(s);
}

static void test_events(void **state)
{
    (void)state;
    obsd_streams *s = obsd_streams_new(4, 4, 1 << 30);
    obsd_sub sub = {.park = on_park, .wake = on_wake};
    char buf[512];
    assert_int_equal(obsd_streams_subscribe(s, "live", &sub, 1000), 0); /* before any frame */
    parked = woken = 0;
    assert_int_equal(obsd_streams_next_event(s, &sub, buf, sizeof buf, 1000), 0);
    assert_int_equal(parked, 1);
    obsd_streams_add(s, "live", frame(8, 6, 1));
    obsd_streams_add(s, "live", frame(8, 6, 1)); /* woken once: it was parked once */
    assert_int_equal(woken, 1);
    assert_true(obsd_streams_next_event(s, &sub, buf, sizeof buf, 1000) > 0);
    assert_non_null(strstr(buf, "\"frame\":2,\"width\":8,\"height\":6")); /* only the newest */
    assert_int_equal(obsd_streams_next_event(s, &sub, buf, sizeof buf, 1000), 0);
    /* keep-alive: the tick wakes it when due, then a comment is written */
    obsd_streams_tick(s, 1000 + OBSD_SSE_KEEPALIVE_MS - 1);
    assert_int_equal(woken, 1);
    obsd_streams_tick(s, 1000 + OBSD_SSE_KEEPALIVE_MS);
    assert_int_equal(woken, 2);
    assert_true(obsd_streams_next_event(s, &sub, buf, sizeof buf, 1000 + OBSD_SSE_KEEPALIVE_MS) > 0);
    assert_int_equal(buf[0], ':');
    assert_int_equal(obsd_streams_next_event(s, &sub, buf, sizeof buf, 1000 + OBSD_SSE_KEEPALIVE_MS), 0);
    /* shutdown: woken, told, closed; no new subscribers */
    obsd_streams_end_all(s);
    assert_int_equal(woken, 3);
    assert_true(obsd_streams_next_event(s, &sub, buf, sizeof buf, 0) > 0);
    assert_non_null(strstr(buf, "shutting down"));
    assert_int_equal(obsd_streams_next_event(s, &sub, buf, sizeof buf, 0), -1);
    obsd_sub late = {.park = on_park, .wake = on_wake};
    assert_int_equal(obsd_streams_subscribe(s, "live", &late, 0), -1);
    obsd_streams_unsubscribe(s, &sub);
    obsd_streams_free(s);
}

static void test_names_and_json(void **state)
{
    (void)state;
    assert_true(obsd_stream_name_ok("shot_010.v2-final"));
    assert_false(obsd_stream_name_ok(""));
    assert_false(obsd_stream_name_ok("a/b"));
    assert_false(obsd_stream_name_ok("a b"));
    assert_false(obsd_stream_name_ok("\"x\""));
    char longname[80];
    memset(longname, 'a', 65);
    longname[65] = '\0';
    assert_false(obsd_stream_name_ok(longname));
    longname[64] = '\0';
    assert_true(obsd_stream_name_ok(longname));

    obsd_streams *s = obsd_streams_new(4, 4, 1 << 30);
    assert_int_equal(obsd_streams_add(s, "bad name", frame(2, 2, 1)), 0); /* refused, freed */
    obsd_frame *f = frame(2, 2, 1);
    static const char q[] = "radius\0" "0.25\0" "radius\0" "0.5\0";
    f->query = malloc(sizeof q);
    memcpy(f->query, q, sizeof q);
    f->query_len = sizeof q - 1;
    obsd_streams_add(s, "j", f);
    char *list = obsd_streams_list_json(s);
    assert_non_null(strstr(list, "\"name\":\t\"j\""));
    free(list);
    int found;
    char *one = obsd_streams_stream_json(s, "j", &found);
    assert_true(found);
    assert_non_null(strstr(one, "\"radius\":\t\"0.5\"")); /* the last wins */
    assert_null(strstr(one, "0.25"));
    free(one);
    assert_null(obsd_streams_stream_json(s, "nope", &found));
    assert_false(found);
    obsd_streams_free(s);
}

/* A deep frame's JSON and event say so; the params are keyed by the
 * table's names; the camera is the projection's fov_y, near and far. */
static void test_deep_params_camera(void **state)
{
    (void)state;
    obsd_streams *s = obsd_streams_new(4, 4, 1 << 30);
    obsd_frame *f = frame(4, 2, 1);
    size_t flat_bytes = obsd_frame_bytes(f);
    f->deep = 1;
    f->ao_front = (obs_image){4, 2, 1, calloc(8, sizeof(float))};
    assert_int_equal(obsd_frame_bytes(f), flat_bytes + 8 * sizeof(float)); /* the front AO counts */
    static const char q[] = "fov-y\0" "40\0" "fov_y\0" "45\0" "deep_layers\0" "3\0";
    f->query = malloc(sizeof q);
    memcpy(f->query, q, sizeof q);
    f->query_len = sizeof q - 1;
    /* OpenGL perspective, fov_y 50, near 0.05, far 100 (row-major) */
    const double t = 1.0 / tan(25.0 * M_PI / 180.0), n = 0.05, fa = 100.0;
    float *p = f->camera.projection;
    p[0] = (float)t; /* aspect 1 */
    p[5] = (float)t;
    p[10] = (float)(-(fa + n) / (fa - n));
    p[11] = (float)(-2.0 * fa * n / (fa - n));
    p[14] = -1.0f;
    f->camera.has_projection = 1;
    obsd_sub sub = {.park = on_park, .wake = on_wake};
    assert_int_equal(obsd_streams_subscribe(s, "d", &sub, 0), 0);
    obsd_streams_add(s, "d", f);
    char buf[512];
    assert_true(obsd_streams_next_event(s, &sub, buf, sizeof buf, 0) > 0);
    assert_non_null(strstr(buf, "\"color\":false,\"deep\":true,"));
    int found;
    char *one = obsd_streams_stream_json(s, "d", &found);
    assert_non_null(strstr(one, "\"deep\":\ttrue"));
    assert_non_null(strstr(one, "\"fov_y\":\t\"45\"")); /* fov-y and fov_y are one; the last wins */
    assert_null(strstr(one, "fov-y"));
    assert_null(strstr(one, "\"40\""));
    assert_non_null(strstr(one, "\"camera\":\t{\n\t\t\t\t\"fov_y\":\t50,\n\t\t\t\t\"near\":\t0.05,"));
    free(one);
    /* orthographic (P[14] 0): no camera to show */
    obsd_frame *o = frame(4, 2, 1);
    o->camera.has_projection = 1;
    o->camera.projection[0] = o->camera.projection[5] = o->camera.projection[15] = 1.0f;
    obsd_streams_add(s, "o", o);
    one = obsd_streams_stream_json(s, "o", &found);
    assert_null(strstr(one, "camera"));
    assert_non_null(strstr(one, "\"deep\":\tfalse"));
    free(one);
    obsd_streams_unsubscribe(s, &sub);
    obsd_streams_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frames_bounded),
        cmocka_unit_test(test_bytes_bounded),
        cmocka_unit_test(test_streams_bounded_and_refs),
        cmocka_unit_test(test_events),
        cmocka_unit_test(test_names_and_json),
        cmocka_unit_test(test_deep_params_camera),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
