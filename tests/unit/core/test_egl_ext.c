/* The EGL device platform's client-extension check against the strings
 * real drivers list: NVIDIA's (580.159.04, an H200) names only
 * EGL_EXT_device_base for device enumeration, Mesa's names both it and
 * EGL_EXT_device_enumeration; both must pass, and a driver without
 * either is refused naming what is missing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "gl/backend.h"

static const char nvidia_580[] =
    "EGL_EXT_platform_base EGL_EXT_device_base EGL_KHR_client_get_all_proc_addresses "
    "EGL_EXT_client_extensions EGL_KHR_debug EGL_KHR_platform_x11 EGL_EXT_platform_x11 "
    "EGL_EXT_platform_device EGL_MESA_platform_surfaceless EGL_EXT_explicit_device";

static const char mesa_22[] =
    "EGL_EXT_device_base EGL_EXT_device_enumeration EGL_EXT_device_query EGL_EXT_platform_base "
    "EGL_KHR_client_get_all_proc_addresses EGL_EXT_client_extensions EGL_KHR_debug "
    "EGL_EXT_platform_device EGL_MESA_platform_surfaceless";

static void test_drivers_pass(void **state)
{
    char err[OBS_ERR_LEN] = "";
    (void)state;
    assert_int_equal(obs__egl_device_client_ok(nvidia_580, err), 1);
    assert_int_equal(obs__egl_device_client_ok(mesa_22, err), 1);
}

static void test_missing_named(void **state)
{
    char err[OBS_ERR_LEN] = "";
    (void)state;
    /* device_base as a prefix of another name does not count */
    assert_int_equal(obs__egl_device_client_ok("EGL_EXT_platform_device EGL_EXT_device_base_x", err), 0);
    assert_non_null(strstr(err, "EGL_EXT_device_enumeration nor EGL_EXT_device_base"));
    assert_int_equal(obs__egl_device_client_ok("EGL_EXT_device_base EGL_EXT_platform_base", err), 0);
    assert_non_null(strstr(err, "EGL_EXT_platform_device is not available"));
    assert_int_equal(obs__egl_device_client_ok(NULL, err), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drivers_pass),
        cmocka_unit_test(test_missing_named),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
