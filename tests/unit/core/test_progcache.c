/* The program cache (core/gl/progcache.c): a second context loads what
 * the first built and the loaded program draws the same pixels; damaged,
 * truncated and foreign entries are ignored, counted and rebuilt; a
 * folder that cannot be made is no cache with one log line; Mesa's shader
 * cache is turned on for the folder even under MESA_SHADER_CACHE_DISABLE
 * (Mesa offers no binary format without it). */
#include <errno.h>
#include <nettle/sha2.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "testutil.h"

#include "context.h"
#include "gl/progcache.h"
#include "obs_shaders.h"

static const char frag_src[] = "#version 430 core\n"
                               "#define VALUE vec4(0.25, 0.5, 0.75, 1.0)\n"
                               "out vec4 o;\nvoid main() { o = VALUE; }\n";

/* Log lines that mention the program cache, counted per test. */
static int cache_lines;
static void count_log(void *user, obs_log_level level, const char *msg)
{
    (void)user;
    (void)level;
    if (strstr(msg, "program cache"))
        cache_lines++;
}

static char *new_dir(void)
{
    char tmpl[512];
    snprintf(tmpl, sizeof tmpl, "%s/progcache.XXXXXX", obs_test_tmp());
    char *d = mkdtemp(tmpl);
    assert_non_null(d);
    return strdup(d);
}

static obs_ctx *cache_ctx(const char *dir)
{
    obs_ctx *ctx = NULL;
    char err[OBS_ERR_LEN] = "";
    obs_ctx_desc d = {.cache_dir = dir, .log = count_log};
    if (obs_ctx_create(&d, &ctx, err) != OBS_OK)
        fail_msg("context: %s", err);
    return ctx;
}

/* Builds the test program on ctx; 0 when it failed. */
static GLuint build(obs_ctx *ctx, const char *frag)
{
    char err[OBS_ERR_LEN] = "";
    GLuint prog = 0;
    assert_int_equal(obs__ctx_bind(ctx, err), OBS_OK);
    const char *parts[] = {frag};
    if (obs__gl_program("test", obs__shader_fullscreen_vert, parts, 1, &prog, err) != OBS_OK)
        fail_msg("%s", err);
    return prog;
}

/* Draws prog over a 4x4 float target; the first pixel's RGBA. */
static void draw_pixel(obs_ctx *ctx, GLuint prog, float out[4])
{
    GLuint tex, fbo;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, 4, 4);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    glViewport(0, 0, 4, 4);
    glUseProgram(prog);
    glBindVertexArray(ctx->dev.vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, out);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__gl_check("draw", err), OBS_OK);
}

static void counts(obs_ctx *ctx, unsigned long compiled, unsigned long loaded,
                   unsigned long rejected)
{
    obs_ctx_info ci;
    obs_ctx_get_info(ctx, &ci);
    assert_int_equal(ci.programs_compiled, compiled);
    assert_int_equal(ci.programs_loaded, loaded);
    assert_int_equal(ci.programs_rejected, rejected);
}

/* The entry of the test program under dir. */
static void entry_path(obs_ctx *ctx, const char *frag, char *buf, size_t n)
{
    obs__progkey key;
    const char *parts[] = {frag};
    assert_int_equal(obs__progkey_make(&ctx->dev.cache, obs__shader_fullscreen_vert, parts, 1, &key), 0);
    obs__progcache_entry_path(&ctx->dev.cache, &key, buf, n);
    obs__progkey_free(&key);
}

static unsigned char *slurp(const char *path, size_t *len)
{
    unsigned char *b = obs_test_slurp(path, len);
    assert_non_null(b);
    return b;
}

static void spit(const char *path, const unsigned char *b, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, len, f), len);
    fclose(f);
}

/* The header of an entry as progcache.c writes it. */
typedef struct head {
    char magic[8];
    uint32_t key_len, format, bin_len, reserved;
    uint8_t digest[SHA256_DIGEST_SIZE];
} head;

static void redigest(unsigned char *b)
{
    head h;
    memcpy(&h, b, sizeof h);
    struct sha256_ctx c;
    sha256_init(&c);
    sha256_update(&c, h.key_len + h.bin_len, b + sizeof h);
    sha256_digest(&c, sizeof h.digest, h.digest);
    memcpy(b, &h, sizeof h);
}

/* First in the file: Mesa reads MESA_SHADER_CACHE_DISABLE when its
 * display is first initialised. */
static void test_mesa_disable_is_overridden(void **state)
{
    (void)state;
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
    char *dir = new_dir();
    obs_ctx *ctx = cache_ctx(dir);
    if (!strstr(ctx->dev.vendor, "Mesa")) {
        print_message("skip: %s is not Mesa\n", ctx->dev.renderer);
    } else {
        assert_true(ctx->dev.cache.formats > 0);
        assert_string_equal(getenv("MESA_SHADER_CACHE_DISABLE"), "false");
        assert_string_equal(getenv("MESA_SHADER_CACHE_DIR"), dir);
    }
    obs_ctx_destroy(ctx);
    free(dir);
}

static void test_second_context_loads(void **state)
{
    (void)state;
    char *dir = new_dir(), path[4300];
    float a[4], b[4];
    obs_ctx *ctx = cache_ctx(dir);
    obs_ctx_info ci;
    obs_ctx_get_info(ctx, &ci);
    assert_non_null(ci.cache_dir);
    assert_string_equal(ci.cache_dir, dir);
    assert_int_equal(ci.cache_writable, 1);
    GLuint p = build(ctx, frag_src);
    counts(ctx, 1, 0, 0);
    entry_path(ctx, frag_src, path, sizeof path);
    assert_true(obs_test_exists(path));
    draw_pixel(ctx, p, a);
    obs_ctx_destroy(ctx);

    ctx = cache_ctx(dir);
    p = build(ctx, frag_src);
    counts(ctx, 0, 1, 0);
    draw_pixel(ctx, p, b);
    assert_memory_equal(a, b, sizeof a);
    assert_true(a[0] == 0.25f && a[1] == 0.5f && a[2] == 0.75f && a[3] == 1.0f);
    /* another define is another program */
    static const char other[] = "#version 430 core\n#define VALUE vec4(1.0)\n"
                                "out vec4 o;\nvoid main() { o = VALUE; }\n";
    build(ctx, other);
    counts(ctx, 1, 1, 0);
    obs_ctx_destroy(ctx);
    free(dir);
}

/* Each damage: what it does to the entry's bytes (b, *len). */
enum { FLIP_BINARY, FLIP_KEY, TRUNCATE_HALF, TRUNCATE_HEAD, EMPTY, TRAILING, NOT_ENTRY,
       GARBAGE_BINARY, OTHER_RENDERER, OTHER_PROGRAM, DAMAGE_COUNT };
static const char *const damage_names[DAMAGE_COUNT] = {
    "a flipped byte in the binary", "a flipped byte in the key", "truncated to half",
    "truncated inside the header", "empty", "trailing bytes", "not an entry",
    "a binary the driver refuses (digest valid)", "another renderer's key (digest valid)",
    "another program's entry under this name"};

static void damage(int kind, unsigned char **bp, size_t *len, const unsigned char *other,
                   size_t other_len)
{
    unsigned char *b = *bp;
    head h;
    memcpy(&h, b, sizeof h);
    switch (kind) {
    case FLIP_BINARY: b[*len - 7] ^= 0x40; break;
    case FLIP_KEY: b[sizeof h + h.key_len / 2] ^= 0x01; break;
    case TRUNCATE_HALF: *len /= 2; break;
    case TRUNCATE_HEAD: *len = 20; break;
    case EMPTY: *len = 0; break;
    case TRAILING:
        *bp = b = realloc(b, *len + 5);
        memcpy(b + *len, "extra", 5);
        *len += 5;
        break;
    case NOT_ENTRY: memcpy(b, "GARBAGE!", 8); break;
    case GARBAGE_BINARY:
        for (uint32_t i = 0; i < h.bin_len; i++)
            b[sizeof h + h.key_len + i] = (unsigned char)(i * 131u + 7u);
        redigest(b);
        break;
    case OTHER_RENDERER: {
        /* the renderer string is the key's third field */
        unsigned char *k = b + sizeof h;
        uint64_t n;
        for (int f = 0; f < 2; f++) {
            memcpy(&n, k, sizeof n);
            k += sizeof n + n;
        }
        memcpy(&n, k, sizeof n);
        assert_true(n > 0);
        k[sizeof n] ^= 0x20; /* llvmpipe -> Llvmpipe */
        redigest(b);
        break;
    }
    case OTHER_PROGRAM:
        *bp = b = realloc(b, other_len);
        memcpy(b, other, other_len);
        *len = other_len;
        break;
    }
}

static void test_damaged_entries_are_rebuilt(void **state)
{
    (void)state;
    static const char other[] = "#version 430 core\nout vec4 o;\nvoid main() { o = vec4(0.5); }\n";
    for (int kind = 0; kind < DAMAGE_COUNT; kind++) {
        char *dir = new_dir(), path[4300], other_path[4300];
        size_t len, other_len;
        float a[4];
        obs_ctx *ctx = cache_ctx(dir);
        build(ctx, frag_src);
        build(ctx, other);
        entry_path(ctx, frag_src, path, sizeof path);
        entry_path(ctx, other, other_path, sizeof other_path);
        obs_ctx_destroy(ctx);
        unsigned char *b = slurp(path, &len), *o = slurp(other_path, &other_len);
        damage(kind, &b, &len, o, other_len);
        spit(path, b, len);
        free(b);
        free(o);

        ctx = cache_ctx(dir);
        GLuint p = build(ctx, frag_src);
        print_message("entry damaged: %s\n", damage_names[kind]);
        counts(ctx, 1, 0, 1);
        draw_pixel(ctx, p, a);
        assert_true(a[0] == 0.25f && a[1] == 0.5f && a[2] == 0.75f);
        obs_ctx_destroy(ctx);
        /* the rebuilt entry is whole again */
        ctx = cache_ctx(dir);
        build(ctx, frag_src);
        counts(ctx, 0, 1, 0);
        obs_ctx_destroy(ctx);
        free(dir);
    }
}

/* A folder that cannot be made: no cache, one log line, programs built. */
static void test_unusable_folder(void **state)
{
    (void)state;
    const char *file = obs_test_tmp_file("progcache-not-a-folder", "x");
    char under_file[600];
    snprintf(under_file, sizeof under_file, "%s/cache", file);
    const char *dirs[] = {"/proc/obscura-no-such/cache", under_file};
    for (size_t k = 0; k < 2; k++) {
        cache_lines = 0;
        obs_ctx *ctx = cache_ctx(dirs[k]);
        obs_ctx_info ci;
        obs_ctx_get_info(ctx, &ci);
        assert_null(ci.cache_dir);
        assert_int_equal(cache_lines, 1);
        build(ctx, frag_src);
        counts(ctx, 1, 0, 0);
        assert_int_equal(cache_lines, 1);
        obs_ctx_destroy(ctx);
    }
    /* a folder others may write to: off, one line naming the mode */
    char *dir = new_dir(), progs[600];
    obs_ctx *ctx = cache_ctx(dir);
    obs_ctx_destroy(ctx);
    snprintf(progs, sizeof progs, "%s/programs", dir);
    for (int k = 0; k < 2; k++) {
        assert_int_equal(chmod(progs, k ? 0775 : 0777), 0);
        cache_lines = 0;
        ctx = cache_ctx(dir);
        obs_ctx_info ci;
        obs_ctx_get_info(ctx, &ci);
        assert_null(ci.cache_dir);
        assert_int_equal(cache_lines, 1);
        obs_ctx_destroy(ctx);
    }
    free(dir);
    /* no folder at all: the caller is told why */
    char buf[64], why[OBS_ERR_LEN];
    unsetenv("OBSCURA_CACHE_DIR");
    setenv("XDG_CACHE_HOME", "relative/is/ignored", 1);
    char *home = getenv("HOME") ? strdup(getenv("HOME")) : NULL;
    unsetenv("HOME");
    assert_string_equal(obs_cache_dir_default(NULL, buf, sizeof buf, why), "");
    assert_non_null(strstr(why, "program cache off"));
    setenv("XDG_CACHE_HOME", "/x", 1);
    assert_string_equal(obs_cache_dir_default(NULL, buf, sizeof buf, why), "/x/obscura");
    assert_string_equal(why, "");
    setenv("OBSCURA_CACHE_DIR", "", 1); /* set and empty: off, silently */
    assert_string_equal(obs_cache_dir_default(NULL, buf, sizeof buf, why), "");
    assert_string_equal(why, "");
    assert_string_equal(obs_cache_dir_default("/given", buf, sizeof buf, why), "/given");
    unsetenv("OBSCURA_CACHE_DIR");
    unsetenv("XDG_CACHE_HOME");
    if (home) {
        setenv("HOME", home, 1);
        char want[600], got[600];
        snprintf(want, sizeof want, "%s/.cache/obscura", home);
        assert_string_equal(obs_cache_dir_default(NULL, got, sizeof got, why), want);
        free(home);
    }
}

/* A folder that can be read but not written: entries load, none is
 * stored (as root every folder is writable: skipped). */
static void test_read_only_folder(void **state)
{
    (void)state;
    if (geteuid() == 0) {
        print_message("skip: root writes to any folder\n");
        return;
    }
    char *dir = new_dir(), progs[600];
    obs_ctx *ctx = cache_ctx(dir);
    build(ctx, frag_src);
    obs_ctx_destroy(ctx);
    snprintf(progs, sizeof progs, "%s/programs", dir);
    assert_int_equal(chmod(progs, 0555), 0);
    cache_lines = 0;
    ctx = cache_ctx(dir);
    obs_ctx_info ci;
    obs_ctx_get_info(ctx, &ci);
    assert_non_null(ci.cache_dir);
    assert_int_equal(ci.cache_writable, 0);
    assert_int_equal(cache_lines, 1);
    build(ctx, frag_src);
    counts(ctx, 0, 1, 0);
    static const char other[] = "#version 430 core\nout vec4 o;\nvoid main() { o = vec4(0.125); }\n";
    build(ctx, other);
    counts(ctx, 1, 1, 0);
    obs_ctx_destroy(ctx);
    chmod(progs, 0755);
    free(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mesa_disable_is_overridden),
        cmocka_unit_test(test_second_context_loads),
        cmocka_unit_test(test_damaged_entries_are_rebuilt),
        cmocka_unit_test(test_unusable_folder),
        cmocka_unit_test(test_read_only_folder),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
