/* The memory a process may use: the machine's physical memory, or the
 * memory limit of its control group when that is lower.  A render-farm
 * job (Slurm's cgroup plugin), a container (Docker, Kubernetes) or a
 * systemd unit with MemoryMax runs under such a limit, and a budget taken
 * from the machine's memory alone could exceed it: the kernel would end
 * the process instead of the frame running in bands.
 *
 * The limits, as the kernel documents them (Documentation/admin-guide/
 * cgroup-v2.rst, cgroup-v1/memory.rst): /proc/self/cgroup names the
 * process's group, "0::PATH" on the unified hierarchy (v2, file
 * memory.max, "max" for none) and "N:memory:PATH" (or a list of
 * controllers with memory among them) on v1 (memory.limit_in_bytes, a
 * huge number for none).  A group is also held by its ancestors' limits,
 * so every level from PATH up to the hierarchy's root is read, the
 * smallest counting.  Inside a container the hierarchy is often mounted
 * at the container's own group, where PATH (the host's) does not exist:
 * the root's file is then the container's limit, read all the same. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "obscura/obscura.h"
#include "internal.h"

/* The number in FILE (a limit in bytes); 0 when absent, "max" or unreadable. */
static size_t read_limit(const char *file)
{
    FILE *f = fopen(file, "r");
    if (!f)
        return 0;
    char line[64];
    unsigned long long v = 0;
    if (fgets(line, sizeof line, f) && strncmp(line, "max", 3) != 0 && sscanf(line, "%llu", &v) != 1)
        v = 0;
    fclose(f);
    return v > (unsigned long long)SIZE_MAX ? 0 : (size_t)v;
}

/* The smallest limit in DIR/PATH/NAME and each ancestor of PATH up to DIR/NAME. */
static size_t walk_up(const char *dir, const char *path, const char *name, size_t best)
{
    char p[PATH_MAX], file[PATH_MAX + 64];
    if (snprintf(p, sizeof p, "%s", path) >= (int)sizeof p)
        return best;
    for (;;) {
        size_t n = strlen(p);
        while (n > 0 && p[n - 1] == '/')
            p[--n] = 0;
        if (snprintf(file, sizeof file, "%s%s%s/%s", dir, n && p[0] != '/' ? "/" : "", p, name) <
            (int)sizeof file) {
            size_t v = read_limit(file);
            if (v && (!best || v < best))
                best = v;
        }
        char *slash = strrchr(p, '/');
        if (!n || !slash)
            return best;
        *slash = 0;
    }
}

size_t obs__memory_cgroup_limit(const char *proc_cgroup, const char *sys_cgroup)
{
    FILE *f = fopen(proc_cgroup, "r");
    if (!f)
        return 0;
    char line[PATH_MAX + 128], dir[PATH_MAX];
    size_t best = 0;
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\n")] = 0;
        char *c1 = strchr(line, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
        if (!c2)
            continue;
        *c1 = *c2 = 0;
        const char *ctrl = c1 + 1, *path = c2 + 1;
        if (!*ctrl) { /* v2: the unified mount, or its hybrid place */
            snprintf(dir, sizeof dir, "%s", sys_cgroup);
            best = walk_up(dir, path, "memory.max", best);
            snprintf(dir, sizeof dir, "%s/unified", sys_cgroup);
            best = walk_up(dir, path, "memory.max", best);
            continue;
        }
        for (const char *t = ctrl; t; t = strchr(t, ',') ? strchr(t, ',') + 1 : NULL)
            if (!strncmp(t, "memory", 6) && (t[6] == ',' || !t[6])) {
                snprintf(dir, sizeof dir, "%s/memory", sys_cgroup);
                best = walk_up(dir, path, "memory.limit_in_bytes", best);
            }
    }
    fclose(f);
    return best;
}

/* the default budget of `usable` bytes of usable memory */
static size_t default_budget(size_t usable)
{
    return usable ? usable / 4 : (size_t)1 << 31; /* a quarter of the usable memory; not known: 2 GiB */
}

size_t obs_cpu_memory_budget(const obs_cpu_options *opt)
{
    if (opt && opt->max_memory > 0)
        return opt->max_memory;
    return default_budget(obs_cpu_memory_usable());
}

void obs_cpu_memory_default_text(char *buf, size_t n)
{
    size_t usable = obs_cpu_memory_usable(), mib = default_budget(usable) >> 20;
    if (usable)
        snprintf(buf, n, "%zu MiB (default: a quarter of %.1f GiB usable; --max-memory MIB sets it)", mib,
                 (double)usable / 1073741824.0);
    else
        snprintf(buf, n, "%zu MiB (default: the usable memory is not known; --max-memory MIB sets it)",
                 mib);
}

size_t obs_cpu_memory_usable(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    size_t phys = pages > 0 && page > 0 ? (size_t)pages * (size_t)page : 0;
    size_t lim = obs__memory_cgroup_limit("/proc/self/cgroup", "/sys/fs/cgroup");
    return lim && (!phys || lim < phys) ? lim : phys;
}
