/* obscura warmup: every program variant a configuration can need, built
 * into the program cache (see warmup.h).
 *
 * The variants are chosen by the chain itself (core/chain/run_gl.c,
 * core/deep/deep_gl.c): from the parameters (method, ao_definition,
 * adaptive, culling, range_check, bleeding, luminance, blur_radius,
 * depth_mode, deep_hull) and from what a frame holds (normals or not,
 * colour or not, flat or deep).  So warmup fixes the parameters and runs
 * the frames that reach every input-dependent choice: one with depth,
 * normals and colour and every output, one with depth alone, and a deep
 * one for each method that takes deep input.  Running real frames, not
 * only linking, matters on llvmpipe: it generates a shader's machine code
 * at its first draw, and Mesa's cache (in the same folder) keeps it. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "obscura/deep.h"
#include "obscura/obscura.h"
#include "warmup.h"

#define W 48
#define H 40

static int verbosity = OBS_LOG_INFO;

static void log_cb(void *user, obs_log_level level, const char *msg)
{
    static const char *const names[] = {"error", "warning", "info", "debug"};
    (void)user;
    if ((int)level <= verbosity)
        fprintf(stderr, "obscura: %s: %s\n", names[level], msg);
}

void cli_warmup_usage(FILE *f)
{
    fprintf(f, "  obscura warmup [--methods all|LIST] [--cache-dir DIR] [--backend B] [parameters]\n"
               "                  builds every program the parameters can need (each method of\n"
               "                  LIST, default the --method given) into the program cache\n");
}

/* Neither side a power of two, as most frames (1920x1080): llvmpipe
 * makes separate variants for power-of-two images; so is the culling
 * pre-pass's 1/8 size. */
/* A floor seen at an angle with a step on it: depth (planar, or ndc in
 * (0, 1)), camera-space normals facing the camera, grey colour. */
typedef struct synth {
    float depth[W * H], normal[W * H * 3], color[W * H * 4];
} synth;

static void make_synth(synth *s, int ndc)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = y * W + x;
            float z = 2.0f + 2.0f * (float)(H - y) / H - (x > W / 2 ? 0.5f : 0.0f);
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

/* The frames of one configuration; OBS_OK, or the first failure. */
static obs_status warm_method(obs_ctx *ctx, const obs_params *p, int deep, char err[OBS_ERR_LEN])
{
    obs_params r;
    obs_params_resolve(p, &r);
    static synth s;
    make_synth(&s, r.depth_mode == OBS_DEPTH_NDC);
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
    obs_status st = OBS_OK;
    for (size_t k = 0; k < sizeof runs / sizeof runs[0] && st == OBS_OK; k++) {
        obs_result res = {0};
        st = obs_run(ctx, runs[k].gb, p, runs[k].outputs, &res, err);
        obs_result_free(&res);
    }
    if (st != OBS_OK || !deep)
        return st;
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

int cli_warmup(int argc, char **argv)
{
    const char *methods = NULL, *cache = NULL, *backend = getenv("OBSCURA_BACKEND");
    obs_params p = {0};
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
            fprintf(stderr, "obscura: warmup: unknown argument '%s'\n", a);
            return EXIT_USAGE;
        }
        snprintf(name, sizeof name, "%.*s", (int)(n - 2), a + 2);
        if (!eq && i + 1 >= argc) {
            fprintf(stderr, "obscura: warmup: --%s needs a value\n", name);
            return EXIT_USAGE;
        }
        const char *v = eq ? eq + 1 : argv[++i];
        if (!strcmp(name, "methods"))
            methods = v;
        else if (!strcmp(name, "cache-dir"))
            cache = v;
        else if (!strcmp(name, "backend"))
            backend = v;
        else if (!obs_param_find(name) || obs_param_set(&p, name, v, err) != OBS_OK) {
            fprintf(stderr, "obscura: warmup: %s\n", err[0] ? err : "unknown option");
            if (!err[0])
                fprintf(stderr, "  (--%s is not a warmup option nor a parameter)\n", name);
            return EXIT_USAGE;
        }
    }
    /* the list of methods, checked before any context exists */
    const char *all = obs_param_find("method")->choices;
    char list[256];
    snprintf(list, sizeof list, "%s", !methods ? "" : strcmp(methods, "all") ? methods : all);
    for (char *c = list; *c; c++)
        if (*c == '|')
            *c = ',';
    for (char *m = list, *next; *list && m; m = next) {
        next = strchr(m, ',');
        size_t len = next ? (size_t)(next++ - m) : strlen(m);
        char one[32];
        snprintf(one, sizeof one, "%.*s", (int)len, m);
        obs_params q = p;
        if (len >= sizeof one || obs_param_set(&q, "method", one, err) != OBS_OK) {
            fprintf(stderr, "obscura: warmup: --methods: '%.*s' is not one of all,%s\n", (int)len, m,
                    all);
            return EXIT_USAGE;
        }
    }

    obs_ctx_desc desc = {.log = log_cb};
    if (backend && *backend && obs_backend_parse(backend, &desc.backend) != OBS_OK) {
        fprintf(stderr, "obscura: warmup: backend '%s' is not one of auto|egl-device|egl-surfaceless|osmesa\n",
                backend);
        return EXIT_USAGE;
    }
    char dir[4096], why[OBS_ERR_LEN];
    desc.cache_dir = obs_cache_dir_default(cache, dir, sizeof dir, why);
    if (!desc.cache_dir[0]) {
        fprintf(stderr, "obscura: warmup: %s\n", why[0] ? why : "the program cache is off (--cache-dir '')");
        return EXIT_FAIL;
    }
    obs_ctx *ctx;
    obs_status s = obs_ctx_create(&desc, &ctx, err);
    if (s != OBS_OK)
        return cli_fail(s, "OpenGL", err);
    obs_ctx_info ci;
    obs_ctx_get_info(ctx, &ci);
    if (!ci.cache_dir || !ci.cache_writable) {
        fprintf(stderr, "obscura: warmup: no writable program cache at %s (see the warning above)\n",
                desc.cache_dir);
        obs_ctx_destroy(ctx);
        return EXIT_FAIL;
    }
    /* a synthetic frame has no camera: a field of view unless one is given */
    if (p.fov_y == 0.0f)
        obs_param_set(&p, "fov_y", "60", err);
    obs_param_set(&p, "normal_space", "camera", err);

    int rc = EXIT_OK, runs = 0;
    if (!*list) {
        obs_params r;
        obs_params_resolve(&p, &r);
        char one[32] = "vaopp";
        /* the configured method's name: the choice at its 1-based index */
        const char *c = all;
        for (int k = 1; k < (int)r.method && c; k++)
            c = strchr(c, '|') ? strchr(c, '|') + 1 : NULL;
        if (c)
            snprintf(one, sizeof one, "%.*s", (int)strcspn(c, "|"), c);
        s = warm_method(ctx, &p, method_deep(one), err);
        runs++;
        if (s != OBS_OK)
            rc = cli_fail(s, one, err);
    }
    for (char *m = list, *next; *list && m && rc == EXIT_OK; m = next) {
        next = strchr(m, ',');
        if (next)
            *next++ = '\0';
        obs_params q = p;
        obs_param_set(&q, "method", m, err);
        s = warm_method(ctx, &q, method_deep(m), err);
        runs++;
        if (s != OBS_OK)
            rc = cli_fail(s, m, err);
        else if (verbosity >= OBS_LOG_DEBUG)
            fprintf(stderr, "obscura: debug: warmup: method %s done\n", m);
    }
    obs_ctx_get_info(ctx, &ci);
    unsigned long compiled = ci.programs_compiled, loaded = ci.programs_loaded,
                  rejected = ci.programs_rejected;
    obs_ctx_destroy(ctx); /* Mesa writes its cache out as the context goes */
    if (rc == EXIT_OK && verbosity >= OBS_LOG_INFO)
        printf("warmup: %s: %lu programs built and stored, %lu already there (%lu damaged or "
               "foreign entries rebuilt), %d configuration%s\n",
               dir, compiled, loaded, rejected, runs, runs == 1 ? "" : "s");
    return rc;
}
