/* The program cache (progcache.h): keys, entries on disk, Mesa's cache
 * pointed at the same folder, and the default folder. */
#include <errno.h>
#include <fcntl.h>
#include <nettle/sha2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gl/gl.h"
#include "gl/progcache.h"

/* The entry's header; the key and the binary follow it. */
#define MAGIC "OBSPRG1\n"
typedef struct entry_head {
    char magic[8];
    uint32_t key_len, format, bin_len, reserved;
    uint8_t digest[SHA256_DIGEST_SIZE]; /* SHA-256 of key then binary */
} entry_head;

/* Bounds on what an entry may hold: a file claiming more is damaged. */
#define KEY_MAX (16u << 20)
#define BIN_MAX (256u << 20)

/* ---- the default folder ------------------------------------------------- */

const char *obs_cache_dir_default(const char *given, char *buf, size_t n, char why[OBS_ERR_LEN])
{
    const char *env = getenv("OBSCURA_CACHE_DIR"), *xdg = getenv("XDG_CACHE_HOME"),
               *home = getenv("HOME");
    if (why)
        why[0] = '\0';
    buf[0] = '\0';
    if (given)
        snprintf(buf, n, "%s", given);
    else if (env)
        snprintf(buf, n, "%s", env);
    else if (xdg && xdg[0] == '/') /* the XDG spec: a relative path is to be ignored */
        snprintf(buf, n, "%s/obscura", xdg);
    else if (home && *home)
        snprintf(buf, n, "%s/.cache/obscura", home);
    else if (why)
        snprintf(why, OBS_ERR_LEN, "program cache off: no folder for it (OBSCURA_CACHE_DIR, "
                 "XDG_CACHE_HOME and HOME are unset; --cache-dir names one)");
    return buf;
}

/* ---- opening ------------------------------------------------------------ */

/* mkdir -p of path (modes 0755: the umask may only take bits away). */
static int make_dirs(const char *path)
{
    char tmp[OBS__CACHE_PATH_LEN + 16];
    if (snprintf(tmp, sizeof tmp, "%s", path) >= (int)sizeof tmp) {
        errno = ENAMETOOLONG;
        return -1;
    }
    for (char *p = tmp + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(tmp, 0755) != 0 && errno != EEXIST)
            return -1;
        *p = '/';
    }
    if (mkdir(tmp, 0755) != 0 && errno != EEXIST)
        return -1;
    struct stat st;
    if (stat(tmp, &st) != 0)
        return -1;
    if (!S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        return -1;
    }
    return 0;
}

/* Mesa reads a boolean variable as true for 1, y, yes, true. */
static int env_true(const char *v)
{
    return v && (!strcmp(v, "1") || !strcasecmp(v, "true") || !strcasecmp(v, "y") ||
                 !strcasecmp(v, "yes"));
}

/* Points Mesa's shader cache at root for this process, before the first
 * context: its multi-file cache keeps, beside the GLSL programs, the
 * machine code llvmpipe generates at the first draw of each variant,
 * which program binaries do not hold.  setenv only when the value
 * differs, so a second context (the daemon recreating one while other
 * threads run) writes nothing. */
static void point_mesa(obs__progcache *pc)
{
    const char *user_dir = getenv("MESA_SHADER_CACHE_DIR");
    if (!user_dir && getenv("MESA_GLSL_CACHE_DIR"))
        user_dir = getenv("MESA_GLSL_CACHE_DIR");
    if (!user_dir)
        setenv("MESA_SHADER_CACHE_DIR", pc->dir, 1);
    const char *dis = getenv("MESA_SHADER_CACHE_DISABLE");
    int overridden = 0;
    if (env_true(dis) || (!dis && env_true(getenv("MESA_GLSL_CACHE_DISABLE")))) {
        setenv("MESA_SHADER_CACHE_DISABLE", "false", 1);
        overridden = 1;
    }
    const char *mesa = getenv("MESA_SHADER_CACHE_DIR");
    obs__logf(pc->log, pc->log_user, OBS_LOG_INFO,
              "program cache: %s (Mesa's shader cache: %s%s%s)", pc->dir,
              user_dir ? "MESA_SHADER_CACHE_DIR " : "", user_dir ? mesa : "here",
              overridden ? "; on in this process although MESA_SHADER_CACHE_DISABLE is set: "
                           "--cache-dir '' turns both off"
                         : "");
}

/* A binary is code the driver runs: a folder others may write to (a
 * shared /tmp, a umask of 0) could hand this process any.  1 (and the one
 * log line) when progs is such a folder. */
static int open_to_others(const char *progs, obs_log_fn log, void *user)
{
    struct stat st;
    if (stat(progs, &st) != 0 || !(st.st_mode & (S_IWGRP | S_IWOTH)))
        return 0;
    obs__logf(log, user, OBS_LOG_WARN,
              "program cache off: %s is writable by %s (mode %03o): chmod go-w it or name "
              "another folder", progs, st.st_mode & S_IWOTH ? "others" : "its group",
              (unsigned)(st.st_mode & 0777));
    return 1;
}

void obs__progcache_open(obs__progcache *pc, const char *root, obs_log_fn log, void *user)
{
    pc->log = log;
    pc->log_user = user;
    pc->dir[0] = '\0';
    pc->writable = 0;
    if (!root || !*root)
        return;
    if (strlen(root) + 64 >= sizeof pc->dir) {
        obs__logf(log, user, OBS_LOG_WARN, "program cache off: the folder name is over %zu characters",
                  sizeof pc->dir - 64);
        return;
    }
    char progs[OBS__CACHE_PATH_LEN + 16], probe[OBS__CACHE_PATH_LEN + 64];
    snprintf(progs, sizeof progs, "%s/programs", root);
    if (make_dirs(progs) != 0) {
        int e = errno;
        struct stat st;
        if (stat(progs, &st) == 0 && S_ISDIR(st.st_mode) && access(progs, R_OK | X_OK) == 0) {
            if (open_to_others(progs, log, user))
                return;
            snprintf(pc->dir, sizeof pc->dir, "%s", root);
            obs__logf(log, user, OBS_LOG_WARN,
                      "program cache %s is read-only (%s): programs are loaded from it, none is stored",
                      root, strerror(e));
            return;
        }
        obs__logf(log, user, OBS_LOG_WARN, "program cache off: cannot create %s: %s", progs,
                  strerror(e));
        return;
    }
    if (open_to_others(progs, log, user))
        return;
    /* a real write, not access(): a read-only mount or an ACL says no here */
    snprintf(probe, sizeof probe, "%s/.probe.%ld", progs, (long)getpid());
    int fd = open(probe, O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) {
        int e = errno;
        snprintf(pc->dir, sizeof pc->dir, "%s", root);
        if (access(progs, R_OK | X_OK) != 0) {
            pc->dir[0] = '\0';
            obs__logf(log, user, OBS_LOG_WARN, "program cache off: %s: %s", progs, strerror(e));
        } else {
            obs__logf(log, user, OBS_LOG_WARN,
                      "program cache %s is read-only (%s): programs are loaded from it, none is stored",
                      root, strerror(e));
        }
        return;
    }
    close(fd);
    unlink(probe);
    snprintf(pc->dir, sizeof pc->dir, "%s", root);
    pc->writable = 1;
    point_mesa(pc);
}

void obs__progcache_attach(obs__progcache *pc, const char *vendor, const char *renderer,
                           const char *version)
{
    GLint n = 0;
    pc->vendor = vendor;
    pc->renderer = renderer;
    pc->version = version;
    glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &n);
    while (glGetError() != GL_NO_ERROR) {
    }
    pc->formats = n > 0 ? n : 0;
    if (pc->dir[0] && !pc->formats)
        obs__logf(pc->log, pc->log_user, OBS_LOG_WARN,
                  "program cache %s unused: the driver (%s) offers no program binary format%s",
                  pc->dir, renderer,
                  getenv("MESA_SHADER_CACHE_DISABLE") ? " (Mesa offers them only while its shader "
                                                        "cache is on)"
                                                      : "");
}

/* ---- keys --------------------------------------------------------------- */

static unsigned char *put_field(unsigned char *p, const char *s, size_t len)
{
    uint64_t n = len;
    memcpy(p, &n, sizeof n);
    memcpy(p + sizeof n, s, len);
    return p + sizeof n + len;
}

static void hex(const uint8_t *d, size_t n, char *out)
{
    static const char digits[] = "0123456789abcdef";
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = digits[d[i] >> 4];
        out[2 * i + 1] = digits[d[i] & 15];
    }
    out[2 * n] = '\0';
}

int obs__progkey_make(const obs__progcache *pc, const char *vert, const char *const *frag_parts,
                      int frag_count, obs__progkey *key)
{
    static const char tag[] = "obscura program cache 1";
    const char *v = pc->vendor ? pc->vendor : "", *r = pc->renderer ? pc->renderer : "",
               *ver = pc->version ? pc->version : "";
    size_t frag_len = 0;
    for (int i = 0; i < frag_count; i++)
        frag_len += strlen(frag_parts[i]);
    size_t len = 6 * sizeof(uint64_t) + strlen(tag) + strlen(v) + strlen(r) + strlen(ver) +
                 strlen(vert) + frag_len;
    memset(key, 0, sizeof *key);
    if (len > KEY_MAX || !(key->bytes = malloc(len)))
        return -1;
    unsigned char *p = key->bytes;
    p = put_field(p, tag, strlen(tag));
    p = put_field(p, v, strlen(v));
    p = put_field(p, r, strlen(r));
    p = put_field(p, ver, strlen(ver));
    p = put_field(p, vert, strlen(vert));
    /* the fragment source is what GL compiles: the parts concatenated */
    uint64_t n = frag_len;
    memcpy(p, &n, sizeof n);
    p += sizeof n;
    for (int i = 0; i < frag_count; i++) {
        size_t l = strlen(frag_parts[i]);
        memcpy(p, frag_parts[i], l);
        p += l;
    }
    key->len = (size_t)(p - key->bytes);
    uint8_t d[SHA256_DIGEST_SIZE];
    struct sha256_ctx h;
    sha256_init(&h);
    sha256_update(&h, key->len, key->bytes);
    sha256_digest(&h, sizeof d, d);
    hex(d, sizeof d, key->name);
    return 0;
}

void obs__progkey_free(obs__progkey *key)
{
    free(key->bytes);
    memset(key, 0, sizeof *key);
}

void obs__progcache_entry_path(const obs__progcache *pc, const obs__progkey *key, char *buf,
                               size_t n)
{
    snprintf(buf, n, "%s/programs/%s.bin", pc->dir, key->name);
}

static void digest_of(const unsigned char *key, size_t key_len, const unsigned char *bin,
                      size_t bin_len, uint8_t out[SHA256_DIGEST_SIZE])
{
    struct sha256_ctx h;
    sha256_init(&h);
    sha256_update(&h, key_len, key);
    sha256_update(&h, bin_len, bin);
    sha256_digest(&h, SHA256_DIGEST_SIZE, out);
}

/* ---- loading ------------------------------------------------------------ */

/* Reads the whole file at path into *buf (at most max bytes); the size
 * read, or -1 (errno ENOENT when there is none). */
static long read_file(const char *path, size_t max, unsigned char **buf)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return -1;
    struct stat st;
    long got = -1;
    *buf = NULL;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || (size_t)st.st_size > max) {
        errno = EFBIG;
        goto done;
    }
    size_t size = (size_t)st.st_size, off = 0;
    if (!(*buf = malloc(size ? size : 1)))
        goto done;
    while (off < size) {
        ssize_t r = read(fd, *buf + off, size - off);
        if (r <= 0) {
            if (r < 0 && errno == EINTR)
                continue;
            break;
        }
        off += (size_t)r;
    }
    got = (long)off;
done:
    close(fd);
    if (got < 0) {
        free(*buf);
        *buf = NULL;
    }
    return got;
}

static int reject(obs__progcache *pc, const obs__progkey *key, const char *why)
{
    pc->rejected++;
    obs__logf(pc->log, pc->log_user, OBS_LOG_INFO, "program cache: entry %.16s ignored (%s); rebuilt",
              key->name, why);
    return 0;
}

int obs__progcache_load(obs__progcache *pc, const obs__progkey *key, GLuint *out)
{
    char path[OBS__CACHE_PATH_LEN + 128];
    unsigned char *buf = NULL;
    if (!pc->dir[0] || !pc->formats)
        return 0;
    obs__progcache_entry_path(pc, key, path, sizeof path);
    long size = read_file(path, sizeof(entry_head) + KEY_MAX + BIN_MAX, &buf);
    if (size < 0)
        return errno == ENOENT ? 0 : reject(pc, key, strerror(errno));
    entry_head h;
    int ok = 0;
    const char *why = NULL;
    if ((size_t)size < sizeof h) {
        why = "truncated";
        goto done;
    }
    memcpy(&h, buf, sizeof h);
    if (memcmp(h.magic, MAGIC, sizeof h.magic) != 0) {
        why = "not an entry";
        goto done;
    }
    if ((size_t)size != sizeof h + (size_t)h.key_len + (size_t)h.bin_len) {
        why = (size_t)size < sizeof h + (size_t)h.key_len + (size_t)h.bin_len ? "truncated"
                                                                               : "wrong size";
        goto done;
    }
    const unsigned char *k = buf + sizeof h, *bin = k + h.key_len;
    if (h.key_len != key->len || memcmp(k, key->bytes, key->len) != 0) {
        why = "another driver's or program's key";
        goto done;
    }
    uint8_t d[SHA256_DIGEST_SIZE];
    digest_of(k, h.key_len, bin, h.bin_len, d);
    if (memcmp(d, h.digest, sizeof d) != 0) {
        why = "digest mismatch: damaged";
        goto done;
    }
    GLuint prog = glCreateProgram();
    GLint linked = 0;
    glProgramBinary(prog, (GLenum)h.format, bin, (GLsizei)h.bin_len);
    GLenum e = glGetError();
    while (glGetError() != GL_NO_ERROR) {
    }
    if (e == GL_NO_ERROR)
        glGetProgramiv(prog, GL_LINK_STATUS, &linked);
    if (!linked) {
        glDeleteProgram(prog);
        why = "the driver refused the binary";
        goto done;
    }
    *out = prog;
    pc->loaded++;
    ok = 1;
done:
    free(buf);
    return ok ? 1 : reject(pc, key, why);
}

/* ---- storing ------------------------------------------------------------ */

static int write_all(int fd, const void *p, size_t n)
{
    const unsigned char *c = p;
    while (n) {
        ssize_t w = write(fd, c, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return -1;
        c += w;
        n -= (size_t)w;
    }
    return 0;
}

static void store_failed(obs__progcache *pc, const char *what, const char *path, int e)
{
    if (pc->store_warned++)
        return;
    obs__logf(pc->log, pc->log_user, OBS_LOG_WARN, "program cache: cannot store %s (%s): %s", path,
              what, strerror(e));
}

void obs__progcache_store(obs__progcache *pc, const obs__progkey *key, GLuint prog)
{
    if (!pc->dir[0] || !pc->writable || !pc->formats)
        return;
    GLint len = 0;
    glGetProgramiv(prog, GL_PROGRAM_BINARY_LENGTH, &len);
    if (len <= 0 || (uint32_t)len > BIN_MAX) {
        while (glGetError() != GL_NO_ERROR) {
        }
        return;
    }
    unsigned char *bin = malloc((size_t)len);
    if (!bin)
        return;
    GLenum format = 0;
    GLsizei got = 0;
    glGetProgramBinary(prog, len, &got, &format, bin);
    if (glGetError() != GL_NO_ERROR || got <= 0) {
        while (glGetError() != GL_NO_ERROR) {
        }
        free(bin);
        return;
    }
    entry_head h = {.key_len = (uint32_t)key->len, .format = format, .bin_len = (uint32_t)got};
    memcpy(h.magic, MAGIC, sizeof h.magic);
    digest_of(key->bytes, key->len, bin, (size_t)got, h.digest);

    char path[OBS__CACHE_PATH_LEN + 128], tmp[OBS__CACHE_PATH_LEN + 192];
    obs__progcache_entry_path(pc, key, path, sizeof path);
    /* unique among processes and among contexts of this one */
    static _Atomic unsigned long seq;
    snprintf(tmp, sizeof tmp, "%s/programs/.%s.%ld.%lu.tmp", pc->dir, key->name, (long)getpid(),
             (unsigned long)seq++);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) {
        store_failed(pc, "create", tmp, errno);
        free(bin);
        return;
    }
    int bad = write_all(fd, &h, sizeof h) || write_all(fd, key->bytes, key->len) ||
              write_all(fd, bin, (size_t)got);
    int e = errno;
    bad |= close(fd) != 0;
    /* no fsync: a crash may leave a short entry, which a reader rejects */
    if (bad || rename(tmp, path) != 0) {
        store_failed(pc, bad ? "write" : "rename", path, bad ? e : errno);
        unlink(tmp);
    }
    free(bin);
}
