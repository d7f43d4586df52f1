/* The usable memory (core/memory.c): the control groups' memory limits,
 * read from a made-up /proc/self/cgroup and cgroup tree in a temporary
 * folder: v2 (memory.max, "max" for none), v1 (memory.limit_in_bytes),
 * the smallest over the group and its ancestors, the container's root
 * when the host's path is not there; and obs_cpu_memory_usable never
 * above the machine's memory. */
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"

static char root[] = "/tmp/obs_memory_XXXXXX";

static void put(const char *rel, const char *text)
{
    char path[512], dir[512];
    snprintf(path, sizeof path, "%s/%s", root, rel);
    /* make every folder on the way */
    for (char *s = path + strlen(root) + 1; (s = strchr(s, '/')); s++) {
        snprintf(dir, sizeof dir, "%.*s", (int)(s - path), path);
        mkdir(dir, 0755);
    }
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static size_t limit(void)
{
    char proc[512], sys[512];
    snprintf(proc, sizeof proc, "%s/proc_cgroup", root);
    snprintf(sys, sizeof sys, "%s/sys", root);
    return obs__memory_cgroup_limit(proc, sys);
}

static int setup(void **state)
{
    (void)state;
    strcpy(root, "/tmp/obs_memory_XXXXXX");
    return mkdtemp(root) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    return system(cmd) == 0 ? 0 : -1;
}

static void test_v2(void **state)
{
    (void)state;
    put("proc_cgroup", "0::/slurm/job_7/step_0\n");
    put("sys/memory.max", "max\n");
    put("sys/slurm/memory.max", "max\n");
    put("sys/slurm/job_7/memory.max", "4294967296\n");
    put("sys/slurm/job_7/step_0/memory.max", "max\n");
    assert_true(limit() == (size_t)4294967296ULL); /* the job's, an ancestor of the step */
    put("sys/slurm/job_7/step_0/memory.max", "1073741824\n");
    assert_true(limit() == (size_t)1073741824ULL); /* the smallest */
}

static void test_v2_none(void **state)
{
    (void)state;
    put("proc_cgroup", "0::/user.slice\n");
    put("sys/memory.max", "max\n");
    put("sys/user.slice/memory.max", "max\n");
    assert_true(limit() == 0);
}

static void test_v1(void **state)
{
    (void)state;
    /* the memory controller among others; the host's path is not in the
     * container's mount: its root holds the container's limit */
    put("proc_cgroup", "9:cpu,cpuacct:/docker/abc\n4:memory:/docker/abc\n0::/\n");
    put("sys/memory/memory.limit_in_bytes", "2147483648\n");
    assert_true(limit() == (size_t)2147483648ULL);
    put("sys/memory/docker/abc/memory.limit_in_bytes", "9223372036854771712\n");
    assert_true(limit() == (size_t)2147483648ULL); /* none there: the root's still counts */
    /* "memoryx" is another controller, not memory */
    put("proc_cgroup", "4:memoryx:/docker/abc\n");
    assert_true(limit() == 0);
}

static void test_missing(void **state)
{
    (void)state;
    assert_true(obs__memory_cgroup_limit("/nonexistent/cgroup", "/nonexistent") == 0);
    put("proc_cgroup", "garbage line\n0::\n");
    assert_true(limit() == 0);
}

static void test_usable(void **state)
{
    (void)state;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    size_t phys = (size_t)pages * (size_t)page, u = obs_cpu_memory_usable();
    assert_true(u > 0 && u <= phys);
    size_t lim = obs__memory_cgroup_limit("/proc/self/cgroup", "/sys/fs/cgroup");
    assert_true(u == (lim && lim < phys ? lim : phys));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_v2, setup, teardown),
        cmocka_unit_test_setup_teardown(test_v2_none, setup, teardown),
        cmocka_unit_test_setup_teardown(test_v1, setup, teardown),
        cmocka_unit_test_setup_teardown(test_missing, setup, teardown),
        cmocka_unit_test(test_usable),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
