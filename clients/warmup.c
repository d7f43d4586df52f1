/* obscura warmup: every program variant a configuration can need, built
 * into the program cache (see warmup.h).
 *
 * The variants are chosen by the chain itself (core/chain/run_gl.c,
 * core/deep/deep_gl.c): from the parameters (method, ao_definition,
 * adaptive, culling, range_check, bleeding, luminance, blur_radius,
 * depth_mode, deep_hull) and from what a frame holds (normals or not,
 * colour or not, flat or deep).  So warmup fixes the parameters and runs
 * the frames that reach every input-dependent choice: with depth,
 * normals and colour for each set of outputs that changes the passes'
 * draw buffers, with depth alone, deep for each method that takes deep
 * input, each at four sizes (below).  Running real frames, not
 * only linking, matters on llvmpipe: it generates a shader's machine code
 * at its first draw, and Mesa's cache (in the same folder) keeps it. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "obscura/deep.h"
#include "obscura/obscura.h"
#include "warmup.h"

/* llvmpipe makes separate machine code for images whose width or height
 * is a power of two (most frames have neither, 1920x1080; DCI 4K,
 * 4096x2160, has one): the four kinds, each with the culling pre-pass's
 * 1/8 size of the same kind. */
static const int sizes[][2] = {{48, 40}, {64, 40}, {48, 32}, {64, 64}};
#define WMAX 64
#define HMAX 64

static int verbosity = OBS_LOG_INFO;

/* The frames' own info lines ("no normal channel", of the synthetic
 * frames) only with -v; the context's and the cache's always. */
static void log_cb(void *user, obs_log_level level, const char *msg)
{
    static const char *const names[] = {"error", "warning", "info", "debug"};
    (void)user;
    if (level == OBS_LOG_INFO && verbosity < OBS_LOG_DEBUG && strncmp(msg, "program cache", 13) &&
        strncmp(msg, "GL context", 10))
        return;
    if ((int)level <= verbosity)
        fprintf(stderr, "obscura: %s: %s\n", names[level], msg);
}

void cli_warmup_usage(FILE *f)
{
    fprintf(f, "  obscura warmup [--methods all|LIST] [--cache-dir DIR] [--backend B] [parameters]\n"
               "                  builds every program the parameters can need (each method of\n"
               "                  LIST, default the --method given) into the program cache\n");
}

/* A floor seen at an angle with a step on it: depth (planar, or ndc in
 * (0, 1)), camera-space normals facing the camera, grey colour. */
typedef struct synth {
    int w, h;
    float depth[WMAX * HMAX], normal[WMAX * HMAX * 3], color[WMAX * HMAX * 4];
} synth;

static void make_synth(synth *s, int w, int h, int ndc)
{
    s->w = w;
    s->h = h;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int i = y * w + x;
            float z = 2.0f + 2.0f * (float)(h - y) / h - (x > w / 2 ? 0.5f : 0.0f);
            s->depth[i] = ndc ? 0.9f + 0.02f * z : z;
            s->normal[3 * i] = 0.0f;
            s->normal[3 * i + 1] = 0.6f;
            s->normal[3 * i + 2] = 0.8f;
            for (int c = 0; c < 4; c++)
                s->color[4 * i + c] = c == 3 ? 1.0f : 0.5f;
        }
}

/* Two samples per pixel: a half-transparent sheet before the floor. */
static obs_status deep_frame(const synth *s, obs_deep_image *d)
{
    memset(d, 0, sizeof *d);
    const int W = s->w, H = s->h;
    d->width = W;
    d->height = H;
    d->has_zback = d->has_alpha = d->has_color = d->has_normal = 1;
    d->offset = calloc((size_t)W * H + 1, sizeof *d->offset);
    d->samples = calloc((size_t)W * H * 2 * OBS_DEEP_CH, sizeof *d->samples);
    if (!d->offset || !d->samples)
        return OBS_NO_MEMORY;
    for (int i = 0; i < W * H; i++) {
        d->offset[i + 1] = d->offset[i] + 2;
        for (int k = 0; k < 2; k++) {
            float *v = d->samples + ((size_t)i * 2 + k) * OBS_DEEP_CH;
            v[OBS_DEEP_Z] = v[OBS_DEEP_ZBACK] = k ? s->depth[i] : s->depth[i] * 0.75f;
            v[OBS_DEEP_A] = k ? 1.0f : 0.5f;
            v[OBS_DEEP_R] = v[OBS_DEEP_G] = v[OBS_DEEP_B] = 0.5f * v[OBS_DEEP_A];
            v[OBS_DEEP_NX] = s->normal[3 * i];
            v[OBS_DEEP_NY] = s->normal[3 * i + 1];
            v[OBS_DEEP_NZ] = s->normal[3 * i + 2];
        }
    }
    return OBS_OK;
}

/* The frames of one configuration at one size; OBS_OK, or the first
 * failure. */
static obs_status warm_size(obs_ctx *ctx, const obs_params *p, int deep, int W, int H,
                            char err[OBS_ERR_LEN])
{
    obs_params r;
    obs_params_resolve(p, &r);
    static synth s;
    make_synth(&s, W, H, r.depth_mode == OBS_DEPTH_NDC);
    obs_gbuffer full = {.width = W, .height = H};
    full.depth = (obs_plane){s.depth, 1, 0};
    full.normal = (obs_plane){s.normal, 3, 0};
    full.color = (obs_plane){s.color, 4, 0};
    obs_gbuffer bare = {.width = W, .height = H, .depth = full.depth};
    /* The outputs pick the draw buffers of the AO and finishing passes
     * and whether the composite runs, and llvmpipe makes a variant of a
     * shader for each set of draw buffers: ao, ao and composite, each
     * debug output alone, and all of them. */
    const unsigned every = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_SAMPLE_COUNT |
                           OBS_OUTPUT_CULL_MASK | OBS_OUTPUT_BLEED | OBS_OUTPUT_LUMINANCE;
    const struct {
        const obs_gbuffer *gb;
        unsigned outputs;
    } runs[] = {{&full, OBS_OUTPUT_AO},
                {&full, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE},
                {&full, OBS_OUTPUT_AO | OBS_OUTPUT_SAMPLE_COUNT},
                {&full, OBS_OUTPUT_AO | OBS_OUTPUT_CULL_MASK},
                {&full, OBS_OUTPUT_AO | OBS_OUTPUT_LUMINANCE},
                {&full, every},
                {&bare, OBS_OUTPUT_AO},
                {&bare, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE}};
    const int half = r.ao_resolution == OBS_RESOLUTION_HALF;
    const unsigned debug = OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_CULL_MASK;
    obs_status st = OBS_OK;
    for (size_t k = 0; k < sizeof runs / sizeof runs[0] && st == OBS_OK; k++) {
        if (half && (runs[k].outputs & debug))
            continue; /* half resolution has no per-pixel debug planes */
        obs_result res = {0};
        st = obs_run(ctx, runs[k].gb, p, runs[k].outputs, &res, err);
        obs_result_free(&res);
    }
    /* ao_resolution half (--quality preview) has passes of its own and
     * runs the AO passes at half size: its frames too, unless the
     * parameters chose the resolution */
    if (st == OBS_OK && !half && p->ao_resolution == 0) {
        obs_params q = *p;
        q.ao_resolution = OBS_RESOLUTION_HALF;
        for (size_t k = 0; k < sizeof runs / sizeof runs[0] && st == OBS_OK; k++) {
            if (runs[k].outputs & debug)
                continue;
            obs_result res = {0};
            st = obs_run(ctx, runs[k].gb, &q, runs[k].outputs, &res, err);
            obs_result_free(&res);
        }
    }
    if (st != OBS_OK || !deep || half)
        return st; /* deep input runs at full resolution only */
    obs_deep_image d;
    obs_deep_result dr = {0};
    if ((st = deep_frame(&s, &d)) == OBS_OK)
        st = obs_deep_run(ctx, &d, p, &dr, err);
    obs_deep_result_free(&dr);
    obs_deep_free(&d);
    return st;
}

/* Methods that take deep input (README, "Deep input"): the deep pass
 * refuses the others. */
static int method_deep(const char *name)
{
    return !strcmp(name, "vaopp") || !strcmp(name, "vao") || !strcmp(name, "hemisphere");
}

/* The command line: warmup's own options and the parameters. */
typedef struct warm_args {
    const char *methods, *cache, *backend;
    obs_params p;
} warm_args;

/* -1 to go on, else the exit status (help, or a usage error said). */
static int parse_args(int argc, char **argv, warm_args *o)
{
    char err[OBS_ERR_LEN] = "";
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *eq = strchr(a, '=');
        char name[64];
        size_t n = eq ? (size_t)(eq - a) : strlen(a);
        if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            verbosity = OBS_LOG_WARN;
            continue;
        }
        if (!strcmp(a, "-v") || !strcmp(a, "--verbose")) {
            verbosity = OBS_LOG_DEBUG;
            continue;
        }
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            cli_warmup_usage(stdout);
            return EXIT_OK;
        }
        if (strncmp(a, "--", 2) != 0 || n - 2 >= sizeof name) {
            fprintf(stderr, "obscura: error: warmup: unknown argument '%s'\n", a);
            return EXIT_USAGE;
        }
        snprintf(name, sizeof name, "%.*s", (int)(n - 2), a + 2);
        if (!eq && i + 1 >= argc) {
            fprintf(stderr, "obscura: error: warmup: --%s needs a value\n", name);
            return EXIT_USAGE;
        }
        const char *v = eq ? eq + 1 : argv[++i];
        if (!strcmp(name, "methods"))
            o->methods = v;
        else if (!strcmp(name, "cache-dir"))
            o->cache = v;
        else if (!strcmp(name, "backend"))
            o->backend = v;
        else if (!obs_param_find(name) || obs_param_set(&o->p, name, v, err) != OBS_OK) {
            fprintf(stderr, "obscura: error: warmup: %s\n", err[0] ? err : "unknown option");
            if (!err[0])
                fprintf(stderr, "  (--%s is not a warmup option nor a parameter)\n", name);
            return EXIT_USAGE;
        }
    }
    return -1;
}

/* --methods as a comma-separated list (empty: none given), each checked
 * before any context exists; -1 to go on, else EXIT_USAGE (said). */
static int method_list(const warm_args *o, const char *all, char list[256])
{
    char err[OBS_ERR_LEN] = "";
    snprintf(list, 256, "%s", !o->methods ? "" : strcmp(o->methods, "all") ? o->methods : all);
    for (char *c = list; *c; c++)
        if (*c == '|')
            *c = ',';
    for (char *m = list, *next; *list && m; m = next) {
        next = strchr(m, ',');
        size_t len = next ? (size_t)(next++ - m) : strlen(m);
        char one[32];
        snprintf(one, sizeof one, "%.*s", (int)len, m);
        obs_params q = o->p;
        if (len >= sizeof one || obs_param_set(&q, "method", one, err) != OBS_OK) {
            fprintf(stderr, "obscura: error: warmup: --methods: '%.*s' is not one of all,%s\n", (int)len, m,
                    all);
            return EXIT_USAGE;
        }
    }
    return -1;
}

/* The methods to warm: the list (split in place), else the configured
 * one (written into one); their count. */
static int method_names(const obs_params *p, const char *all, char *list, char one[32],
                        char **names, int cap)
{
    int nm = 0;
    if (!*list) {
        obs_params r;
        obs_params_resolve(p, &r);
        /* the configured method's name: the choice at its 1-based index */
        const char *c = all;
        for (int k = 1; k < (int)r.method && c; k++)
            c = strchr(c, '|') ? strchr(c, '|') + 1 : NULL;
        if (c)
            snprintf(one, 32, "%.*s", (int)strcspn(c, "|"), c);
        names[nm++] = one;
    }
    for (char *m = list, *next; *list && m && nm < cap; m = next) {
        next = strchr(m, ',');
        if (next)
            *next++ = '\0';
        names[nm++] = m;
    }
    return nm;
}

/* The program counts of the contexts, summed. */
typedef struct warm_counts {
    unsigned long compiled, there, rejected;
} warm_counts;

/* Every method at size k in a fresh context; the exit status. */
static int warm_context(obs_ctx_desc *desc, const obs_params *p, char **names, int nm, size_t k,
                        warm_counts *c)
{
    char err[OBS_ERR_LEN] = "";
    obs_ctx *ctx;
    obs_status s = obs_ctx_create(desc, &ctx, err);
    if (s != OBS_OK)
        return cli_fail(s, "OpenGL", err);
    obs_ctx_info ci;
    obs_ctx_get_info(ctx, &ci);
    if (!ci.cache_dir || !ci.cache_writable) {
        fprintf(stderr, "obscura: error: warmup: no writable program cache at %s (see the warning "
                "above)\n", desc->cache_dir);
        obs_ctx_destroy(ctx);
        return EXIT_FAIL;
    }
    desc->log = NULL; /* the cache's and the context's lines once */
    int rc = EXIT_OK;
    for (int i = 0; i < nm && rc == EXIT_OK; i++) {
        obs_params q = *p;
        obs_param_set(&q, "method", names[i], err);
        s = warm_size(ctx, &q, method_deep(names[i]), sizes[k][0], sizes[k][1], err);
        if (s != OBS_OK)
            rc = cli_fail(s, names[i], err);
        else if (verbosity >= OBS_LOG_DEBUG)
            fprintf(stderr, "obscura: debug: warmup: method %s at %dx%d done\n", names[i],
                    sizes[k][0], sizes[k][1]);
    }
    obs_ctx_get_info(ctx, &ci);
    c->compiled += ci.programs_compiled;
    if (k == 0) /* later contexts load what the first built */
        c->there = ci.programs_loaded;
    c->rejected += ci.programs_rejected;
    obs_ctx_destroy(ctx);
    return rc;
}

int cli_warmup(int argc, char **argv)
{
    warm_args o = {.backend = getenv("OBSCURA_BACKEND")};
    char err[OBS_ERR_LEN] = "";
    int rc = parse_args(argc, argv, &o);
    if (rc >= 0)
        return rc;
    const char *all = obs_param_find("method")->choices;
    char list[256];
    if ((rc = method_list(&o, all, list)) >= 0)
        return rc;

    obs_ctx_desc desc = {.log = log_cb};
    if (o.backend && !strcmp(o.backend, "cpu")) { /* --backend cpu or OBSCURA_BACKEND=cpu */
        fprintf(stderr, "obscura: warmup: the CPU device compiles no programs: nothing to warm "
                        "up (the program cache is for the GL backends)\n");
        return EXIT_OK;
    }
    if (o.backend && *o.backend && obs_backend_parse(o.backend, &desc.backend) != OBS_OK) {
        fprintf(stderr, "obscura: error: warmup: backend '%s' is not one of auto|egl-device|egl-surfaceless|osmesa\n",
                o.backend);
        return EXIT_USAGE;
    }
    char dir[4096], why[OBS_ERR_LEN];
    desc.cache_dir = obs_cache_dir_default(o.cache, dir, sizeof dir, why);
    if (!desc.cache_dir[0]) {
        fprintf(stderr, "obscura: error: warmup: %s\n", why[0] ? why : "the program cache is off (--cache-dir '')");
        return EXIT_FAIL;
    }
    char *names[OBS_METHOD_COUNT + 8];
    char one[32] = "vaopp";
    int nm = method_names(&o.p, all, list, one, names, (int)(sizeof names / sizeof names[0]));
    /* a synthetic frame has no camera: a field of view unless one is given */
    if (o.p.fov_y == 0.0f)
        obs_param_set(&o.p, "fov_y", "60", err);
    obs_param_set(&o.p, "normal_space", "camera", err);

    /* One context per size: llvmpipe's machine code for a frame depends
     * on what the context drew before (measured: one context over every
     * size left a third of a real process's variants out of Mesa's
     * cache), and a real process draws one size from a fresh context. */
    warm_counts c = {0};
    rc = EXIT_OK;
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0] && rc == EXIT_OK; k++)
        rc = warm_context(&desc, &o.p, names, nm, k, &c);
    if (rc == EXIT_OK && verbosity >= OBS_LOG_INFO)
        printf("warmup: %s: %lu programs built and stored, %lu already there (%lu damaged or "
               "foreign entries rebuilt), %d method%s at %d sizes\n",
               dir, c.compiled, c.there, c.rejected, nm, nm == 1 ? "" : "s",
               (int)(sizeof sizes / sizeof sizes[0]));
    return rc;
}
