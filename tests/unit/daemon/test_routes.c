/* The route table (daemon/routes.c): URL paths to routes, exact or by
 * prefix, and routes to the names the metrics label them with. */
#include "testutil.h"

#include "routes.h"

static void test_route_of(void **state)
{
    (void)state;
    assert_int_equal(obsd_route_of("/v1/ao"), OBSD_ROUTE_AO);
    assert_int_equal(obsd_route_of("/metrics"), OBSD_ROUTE_METRICS);
    assert_int_equal(obsd_route_of("/"), OBSD_ROUTE_PAGE);
    assert_int_equal(obsd_route_of("/preview/app.js"), OBSD_ROUTE_PAGE);
    assert_int_equal(obsd_route_of("/v1/streams"), OBSD_ROUTE_STREAMS);
    assert_int_equal(obsd_route_of("/v1/streams/shot/frames"), OBSD_ROUTE_STREAMS);
    assert_int_equal(obsd_route_of("/v1/bakes"), OBSD_ROUTE_BAKES);
    assert_int_equal(obsd_route_of("/v1/bakes/0123456789abcdef/result"), OBSD_ROUTE_BAKES);
    assert_int_equal(obsd_route_of("/v1/bakesx"), OBSD_ROUTE_OTHER);
    /* exact: no prefix match for the others, and "binary" is not a URL */
    assert_int_equal(obsd_route_of("/v1/ao/x"), OBSD_ROUTE_OTHER);
    assert_int_equal(obsd_route_of("binary"), OBSD_ROUTE_OTHER);
    assert_int_equal(obsd_route_of(NULL), OBSD_ROUTE_OTHER);
}

static void test_route_path(void **state)
{
    (void)state;
    assert_string_equal(obsd_route_path(OBSD_ROUTE_AO), "/v1/ao");
    assert_string_equal(obsd_route_path(OBSD_ROUTE_BAKES), "/v1/bakes");
    assert_string_equal(obsd_route_path(OBSD_ROUTE_PAGE), "/");
    assert_string_equal(obsd_route_path(OBSD_ROUTE_BINARY), "binary");
    assert_string_equal(obsd_route_path(OBSD_ROUTE_OTHER), "other");
    assert_string_equal(obsd_route_path(OBSD_ROUTE_COUNT), "other");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_route_of),
        cmocka_unit_test(test_route_path),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
