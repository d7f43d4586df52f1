/* The route table (daemon/routes.c): URL paths to their rows, exact or
 * under a prefix, and the rows' labels (the metrics' route label). */
#include "testutil.h"

#include "http_internal.h"
#include "routes.h"

static const char *label_of(const char *path)
{
    int i = obsd__route_find(path);
    return i < 0 ? "other" : obsd__routes[i].path;
}

static void test_route_find(void **state)
{
    (void)state;
    assert_string_equal(label_of("/v1/ao"), "/v1/ao");
    assert_string_equal(label_of("/metrics"), "/metrics");
    assert_string_equal(label_of("/"), "/");
    assert_string_equal(label_of("/preview/app.js"), "/");
    assert_string_equal(label_of("/v1/streams"), "/v1/streams");
    assert_string_equal(label_of("/v1/streams/shot/frames"), "/v1/streams");
    assert_string_equal(label_of("/v1/bakes"), "/v1/bakes");
    assert_string_equal(label_of("/v1/bakes/0123456789abcdef/result"), "/v1/bakes");
    assert_string_equal(label_of("/v1/bakesx"), "other");
    /* exact: no prefix match for the others, and "binary" is not a URL */
    assert_string_equal(label_of("/v1/ao/x"), "other");
    assert_string_equal(label_of("binary"), "other");
    assert_int_equal(obsd__route_find(NULL), -1);
}

/* The metrics list the routes in this order (the table's), then the
 * binary protocol and the unknown paths. */
static void test_route_order(void **state)
{
    static const char *const want[] = {"/v1/ao", "/v1/params", "/v1/info", "/healthz", "/readyz",
                                       "/metrics", "/v1/streams", "/v1/bakes", "/"};
    (void)state;
    assert_int_equal(obsd__route_count, 9);
    for (int i = 0; i < obsd__route_count; i++)
        assert_string_equal(obsd__routes[i].path, want[i]);
}

/* Every row has its start; a row that reads a body has its body handler. */
static void test_route_rows(void **state)
{
    (void)state;
    for (int i = 0; i < obsd__route_count; i++) {
        const obsd__route *rt = &obsd__routes[i];
        assert_non_null(rt->start);
        if (rt->reads_body)
            assert_non_null(rt->body);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_route_find),
        cmocka_unit_test(test_route_order),
        cmocka_unit_test(test_route_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
