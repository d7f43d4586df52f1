/* The ground-truth commands: a G-buffer rasterised from a mesh
 * (obscura gbuffer) and the ray-traced AO reference (obscura reference).
 * Both take the scene as a mesh file (anything assimp reads) in world
 * space and the camera as a camera JSON. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "obscura/bake.h"
#include "obscura/deep.h"
#include "ground.h"
#include <cjson/cJSON.h>

#include "obscura/io.h"
#include "obscura/mask.h"
#include "obscura/obscura.h"
#include "obscura/reference.h"
#include "obscura/scene.h"


void cli_ground_usage(FILE *f)
{
    fprintf(f,
            "  obscura gbuffer SCENE -o OUT.exr --camera CAM.json [--width W] [--height H]\n"
            "                  [--backend B]    rasterise a mesh (OBJ, PLY, glTF/GLB, OFF, ...)\n"
            "                  into a G-buffer EXR: Z, N (world), Ncam, P, R,G,B (albedo), A\n"
            "                  [--baked]        a level baked by obscura bake (.glb, found by\n"
            "                  its attributes; --baked: required) adds _AO, _AO_SHORT, _AO_LONG,\n"
            "                  the vertex values interpolated\n"
            "                  [--ids]          adds id: 1 + the mesh's index at each pixel (0: none),\n"
            "                  an object mask's id:id=N (prints each ID's mesh and node names),\n"
            "                  and a Cryptomatte layer CryptoObject of the node names;\n"
            "                  with --deep, both per sample (the deep object masks' IDs)\n"
            "                  [--dynamic MODEL.json [--dynamic-nodes PATTERN] [--dynamic-sh S]]\n"
            "                  dynamic objects in the baked level (nodes whose name matches the\n"
            "                  pattern, or with glTF extras \"obscura_dynamic\": true, and their\n"
            "                  children) take the baked channels from obscura bake-dynamic's\n"
            "                  region model at each pixel's position and normal (S: quadratic\n"
            "                  or linear SH)\n"
            "                  [--deep] [--alpha [NAME=]A]...   every fragment into a deep\n"
            "                  EXR (A-buffer): Z, A, R,G,B, N (world); opacity from the\n"
            "                  materials or --alpha (all meshes, or those matching NAME)\n"
            "  obscura reference SCENE -o REF.(exr|png) --camera CAM.json [--distance D]\n"
            "                  [--spp N] [--seed N] [--threads N] [--width W] [--height H]\n"
            "                  [--gbuffer G.exr] [--alpha [NAME=]A]...\n"
            "                  ray-traced AO (Embree): AO.Y and Z; transparent surfaces\n"
            "                  attenuate rays, transparent layers blend by alpha\n"
            "                  [--obscurance SHORT,LONG [--blend B]]   the bake's obscurance\n"
            "                  instead (eq 1, closest hits, rho = 1 - exp(a x), a = ln 0.5 / d;\n"
            "                  opaque): AO.Y = B short + (1 - B) long, AO_SHORT.Y, AO_LONG.Y, Z;\n"
            "                  [--near D]: also AO_NEAR.Y (the AO above at distance D) and\n"
            "                  AO_BOTH.Y = AO_NEAR x AO_LONG (baked long x screen-space's reference)\n"
            "                  [--decorators D.json] [--decorator-source S] [--shrub-density F]\n"
            "                  [--tree-attenuation A]   decorators traced as obscura bake does\n");
}

/* The options both commands share. */
typedef struct ground_args {
    const char *cmd, *scene, *out, *camera, *backend, *gbuffer, *decorators;
    const char *dynamic, *dynamic_nodes; /* gbuffer --dynamic MODEL, --dynamic-nodes */
    int dynamic_linear;
    long width, height, spp, threads;
    unsigned long long seed;
    double distance;
    int quiet, verbose, deep, baked, ids;
    /* --obscurance and --blend, through the bake's table (its ranges and
     * its default blend) */
    int obscurance, blend_given, decor_given;
    double near;
    obs_bake_params bake;
#define MAX_ALPHA_SPECS 64
    const char *alpha[MAX_ALPHA_SPECS]; /* --alpha specs, in order */
    int nalpha;
} ground_args;

static const char *opt_value(const ground_args *a, int argc, char **argv, int *i,
                             const char *name);

/* One of the bake's decorator parameters (reference --obscurance): its
 * value, *key its name; NULL when argv[*i] is none of them. */
static const char *decor_opt(const ground_args *a, int argc, char **argv, int *i,
                             const char **key)
{
    static const char *const rows[] = {"decorator-source", "shrub-density", "tree-attenuation"};
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        const char *v = opt_value(a, argc, argv, i, rows[k]);
        if (v) {
            *key = rows[k];
            return v;
        }
    }
    return NULL;
}

/* "--name VALUE" or "--name=VALUE"; NULL when argv[*i] is not --name. */
static const char *opt_value(const ground_args *a, int argc, char **argv, int *i, const char *name)
{
    const char *s = argv[*i];
    size_t n = strlen(name);
    if (s[0] != '-')
        return NULL;
    s += s[1] == '-' ? 2 : 1;
    if (strncmp(s, name, n) != 0 || (s[n] != '=' && s[n] != '\0'))
        return NULL;
    if (s[n] == '=')
        return s + n + 1;
    if (*i + 1 >= argc)
        cli_die_usage(a->cmd, "option --%s needs a value", name);
    return argv[++*i];
}

static long parse_long(const ground_args *a, const char *name, const char *v, long lo, long hi)
{
    char *end;
    errno = 0;
    long x = strtol(v, &end, 10);
    if (errno || end == v || *end || x < lo || x > hi)
        cli_die_usage(a->cmd, "--%s '%s': expected an integer from %ld to %ld", name, v, lo, hi);
    return x;
}

/* --near, --distance: a positive finite length, else a usage error. */
static double positive_length(const ground_args *a, const char *key, const char *v)
{
    char *end;
    double d = strtod(v, &end);
    if (end == v || *end || !(d > 0) || !isfinite(d))
        cli_die_usage(a->cmd, "--%s '%s': expected a positive length", key, v);
    return d;
}

static void parse(ground_args *a, int argc, char **argv, int reference)
{
    for (int i = 0; i < argc; i++) {
        const char *v, *key = NULL;
        if ((v = opt_value(a, argc, argv, &i, "o")) || (v = opt_value(a, argc, argv, &i, "output")))
            a->out = v;
        else if ((v = opt_value(a, argc, argv, &i, "camera")))
            a->camera = v;
        else if ((v = opt_value(a, argc, argv, &i, "width")))
            a->width = parse_long(a, "width", v, 1, 16384);
        else if ((v = opt_value(a, argc, argv, &i, "height")))
            a->height = parse_long(a, "height", v, 1, 16384);
        else if (!reference && (v = opt_value(a, argc, argv, &i, "backend")))
            a->backend = v;
        else if (!reference && !strcmp(argv[i], "--deep"))
            a->deep = 1;
        else if (!reference && !strcmp(argv[i], "--baked"))
            a->baked = 1;
        else if (!reference && !strcmp(argv[i], "--ids"))
            a->ids = 1;
        else if (!reference && (v = opt_value(a, argc, argv, &i, "dynamic")))
            a->dynamic = v;
        else if (!reference && (v = opt_value(a, argc, argv, &i, "dynamic-nodes")))
            a->dynamic_nodes = v;
        else if (!reference && (v = opt_value(a, argc, argv, &i, "dynamic-sh"))) {
            if (strcmp(v, "linear") && strcmp(v, "quadratic"))
                cli_die_usage(a->cmd, "--dynamic-sh '%s': linear or quadratic", v);
            a->dynamic_linear = !strcmp(v, "linear");
        }
        else if ((v = opt_value(a, argc, argv, &i, "alpha"))) {
            /* A or NAME=A, A in [0, 1]; the name is matched on loading. */
            const char *eq = strrchr(v, '='), *num = eq ? eq + 1 : v;
            char *end;
            double x = strtod(num, &end);
            if (end == num || *end || !(x >= 0.0 && x <= 1.0) || eq == v)
                cli_die_usage(a->cmd, "--alpha '%s': expected A or NAME=A, A from 0 to 1", v);
            if (a->nalpha == MAX_ALPHA_SPECS)
                cli_die_usage(a->cmd, "more than %d --alpha options", MAX_ALPHA_SPECS);
            a->alpha[a->nalpha++] = v;
        }
        else if (reference && (v = opt_value(a, argc, argv, &i, "spp")))
            a->spp = parse_long(a, "spp", v, 1, 1 << 20);
        else if (reference && (v = opt_value(a, argc, argv, &i, "threads")))
            a->threads = parse_long(a, "threads", v, 1, 64);
        else if (reference && (v = opt_value(a, argc, argv, &i, "seed")))
            a->seed = (unsigned long long)parse_long(a, "seed", v, 0, 0x7fffffffL);
        else if (reference && (v = opt_value(a, argc, argv, &i, "gbuffer")))
            a->gbuffer = v;
        else if (reference && (v = opt_value(a, argc, argv, &i, "obscurance"))) {
            char sh[64], lo[64], err[OBS_ERR_LEN] = "";
            const char *comma = strchr(v, ',');
            if (!comma || strchr(comma + 1, ',') || comma == v || !comma[1])
                cli_die_usage(a->cmd, "--obscurance '%s': expected SHORT,LONG (e.g. 2,300)", v);
            snprintf(sh, sizeof sh, "%.*s", (int)(comma - v), v);
            snprintf(lo, sizeof lo, "%s", comma + 1);
            if (obs_bake_param_set(&a->bake, "distance_short", sh, err) != OBS_OK ||
                obs_bake_param_set(&a->bake, "distance_long", lo, err) != OBS_OK)
                cli_die_usage(a->cmd, "--obscurance '%s': %s", v, err);
            a->obscurance = 1;
        } else if (reference && (v = opt_value(a, argc, argv, &i, "decorators"))) {
            a->decorators = v;
        } else if (reference && (v = decor_opt(a, argc, argv, &i, &key))) {
            /* the bake's decorator rows (obscura/bake.h), so that the
             * reference traces the decorators as a bake of the same
             * parameters does */
            char err[OBS_ERR_LEN] = "";
            if (obs_bake_param_set(&a->bake, key, v, err) != OBS_OK)
                cli_die_usage(a->cmd, "--%s '%s': %s", key, v, err);
            a->decor_given = 1;
        } else if (reference && (v = opt_value(a, argc, argv, &i, "near"))) {
            a->near = positive_length(a, "near", v);
        } else if (reference && (v = opt_value(a, argc, argv, &i, "blend"))) {
            char err[OBS_ERR_LEN] = "";
            if (obs_bake_param_set(&a->bake, "blend", v, err) != OBS_OK)
                cli_die_usage(a->cmd, "--blend '%s': %s", v, err);
            a->blend_given = 1;
        } else if (reference && (v = opt_value(a, argc, argv, &i, "distance"))) {
            a->distance = positive_length(a, "distance", v);
        } else if (!strcmp(argv[i], "-q") || !strcmp(argv[i], "--quiet"))
            a->quiet = 1;
        else if (!strcmp(argv[i], "-v") || !strcmp(argv[i], "--verbose"))
            a->verbose = 1;
        else if (argv[i][0] == '-' && argv[i][1])
            cli_die_usage(a->cmd, "unknown option '%s'", argv[i]);
        else if (!a->scene)
            a->scene = argv[i];
        else
            cli_die_usage(a->cmd, "more than one scene ('%s', '%s')", a->scene, argv[i]);
    }
    if (!a->scene)
        cli_die_usage(a->cmd, "no scene file");
    if (!a->out)
        cli_die_usage(a->cmd, "no output file (-o OUT)");
    if (!a->camera && !(reference && a->gbuffer))
        cli_die_usage(a->cmd, "no camera (--camera CAM.json)");
    if ((a->decorators || a->decor_given) && !a->obscurance)
        cli_die_usage(a->cmd, "--decorators and the decorator parameters need --obscurance "
                              "SHORT,LONG");
    if ((a->blend_given || a->near > 0) && !a->obscurance)
        cli_die_usage(a->cmd, "--%s needs --obscurance SHORT,LONG", a->near > 0 ? "near" : "blend");
    if (a->obscurance && a->nalpha)
        cli_die_usage(a->cmd, "--alpha does not apply to --obscurance (every surface is opaque, "
                              "as the bake traces it)");
    if (a->baked && a->deep)
        cli_die_usage(a->cmd, "--baked and --deep: the deep G-buffer does not carry the baked "
                              "channels");
    if (a->dynamic_nodes && !a->dynamic)
        cli_die_usage(a->cmd, "--dynamic-nodes needs --dynamic MODEL.json (the region model of "
                              "obscura bake-dynamic)");
    if (a->dynamic && (a->deep || a->nalpha))
        cli_die_usage(a->cmd, "--dynamic and --%s: the deep G-buffer does not carry the baked "
                              "channels", a->deep ? "deep" : "alpha");
    if (!reference && a->nalpha && !a->deep)
        cli_die_usage(a->cmd, "--alpha needs --deep (the flat G-buffer is the front surface only)");
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* The camera JSON and the image size: the flags, else the JSON's. */
static int load_camera(const ground_args *a, obs_camera *cam, int *w, int *h)
{
    char err[OBS_ERR_LEN] = "";
    int cw = 0, ch = 0;
    obs_status s = obs_camera_read_json(a->camera, cam, &cw, &ch, err);
    if (s != OBS_OK)
        return cli_input_fail(s, a->camera, err);
    if (!cam->has_projection)
        return cli_input_fail(OBS_NO_CAMERA, a->camera, "the camera has no projection (fov_y_deg or projection)");
    *w = a->width ? (int)a->width : cw;
    *h = a->height ? (int)a->height : ch;
    if (*w <= 0 || *h <= 0)
        cli_die_usage(a->cmd, "%s gives no image size: use --width and --height", a->camera);
    if (cw > 0 && ch > 0 && fabs((double)cw / ch - (double)*w / *h) > 1e-3) {
        /* Another aspect: a centred perspective keeps its vertical field
         * of view and widens or narrows horizontally (x scale = y scale /
         * aspect); any other projection is used as it is, stretched. */
        if (obs_camera_fit_aspect(cam, *w, *h)) {
            fprintf(stderr, "obscura: warning: camera %s is %dx%d; rendering %dx%d with its vertical field "
                            "of view\n", a->camera, cw, ch, *w, *h);
        } else {
            fprintf(stderr, "obscura: warning: camera %s is %dx%d, the image %dx%d (aspect "
                            "differs; the projection is stretched)\n", a->camera, cw, ch, *w, *h);
        }
    }
    return EXIT_OK;
}

static void log_cb(void *user, obs_log_level level, const char *msg)
{
    static const char *const names[] = {"error", "warning", "info", "debug"};
    const ground_args *a = user;
    int verbosity = a->quiet ? OBS_LOG_WARN : a->verbose ? OBS_LOG_DEBUG : OBS_LOG_WARN;
    if ((int)level <= verbosity)
        fprintf(stderr, "obscura: %s: %s\n", names[level], msg);
}

/* reference --obscurance: the level read again as the bake reads it,
 * its decorators classified, and the occluders the bake's rays meet
 * (obs_bake_occluders_new); *out NULL when the level has no decorators. */
static int load_occluders(const ground_args *a, obs_bake_occluders **out)
{
    char err[OBS_ERR_LEN] = "", warning[OBS_ERR_LEN] = "";
    char *text = NULL;
    obs_status s;
    *out = NULL;
    obs_bake_params p;
    obs_bake_params_resolve(&a->bake, &p);
    if (p.decorator_source == OBS_BAKE_DECOR_OFF)
        return EXIT_OK;
    if (a->decorators && (s = cli_read_text(a->decorators, &text, err)) != OBS_OK)
        return cli_input_fail(s, a->decorators, err);
    obs_bake_scene bs;
    if ((s = obs_bake_load(a->scene, 0, &bs, err)) != OBS_OK) {
        free(text);
        return cli_input_fail(s, a->scene, err);
    }
    s = obs_bake_occluders_new(&bs, &a->bake, text, out, warning, err);
    obs_bake_scene_free(&bs);
    free(text);
    if (s != OBS_OK)
        return cli_input_fail(s, a->scene, err);
    if (warning[0])
        fprintf(stderr, "obscura: reference: warning: %s\n", warning);
    if (*out && !a->quiet)
        fprintf(stderr, "obscura: info: %s: decorators traced as the bake does (shrubs as fog, "
                        "trees semi-transparent)\n", a->scene);
    return EXIT_OK;
}

static int load_scene(const ground_args *a, obs_scene *scene)
{
    char err[OBS_ERR_LEN] = "";
    double t0 = cli_now_s();
    /* A baked level is read for its _AO attributes, which assimp drops. */
    size_t marked = 0;
    obs_status s = a->dynamic
                       ? obs_scene_load_baked_dynamic(a->scene, a->dynamic_nodes, scene, &marked, err)
                   : a->baked || (!a->deep && !a->nalpha && obs_scene_file_is_baked(a->scene))
                       ? obs_scene_load_baked(a->scene, scene, err)
                       : obs_scene_load(a->scene, scene, err);
    if (s != OBS_OK)
        return cli_input_fail(s, a->scene, err);
    if (a->dynamic && !marked) {
        obs_scene_free(scene);
        return cli_input_fail(OBS_INVALID_ARGUMENT, a->scene,
                              "--dynamic: no node is marked dynamic (--dynamic-nodes PATTERN on "
                              "the nodes' names, or glTF node extras \"obscura_dynamic\": true)");
    }
    for (int k = 0; k < a->nalpha; k++)
        if ((s = obs_scene_set_opacity(scene, a->alpha[k], err)) != OBS_OK) {
            obs_scene_free(scene);
            return cli_input_fail(s, a->scene, err);
        }
    if (!a->quiet)
        fprintf(stderr, "obscura: info: %s: %zu triangles, %zu vertices%s%s%s (%.2f s)\n",
                a->scene, scene->triangle_count, scene->vertex_count,
                scene->albedo ? ", albedo" : "", scene->opacity ? ", opacity" : "",
                !scene->baked ? "" : scene->baked_mask == 7 ? ", baked _AO, _AO_SHORT, _AO_LONG"
                                                            : ", baked _AO",
                cli_now_s() - t0);
    return EXIT_OK;
}

/* ---- obscura gbuffer ------------------------------------------------------ */

/* gbuffer --ids: a Cryptomatte layer "CryptoObject" of the meshes (each
 * named by its node, else its mesh name) as the specification writes one:
 * one rank set, rank 0 the ID of the name's MurmurHash3 (obs_crypto_name_id)
 * with coverage 1 (one sample per pixel), rank 1 empty; the manifest JSON
 * and the layer's attributes into attrs (key, value, ..., NULL; the strings
 * in *store, freed by the caller).  0, or -1 out of memory. */
#define CRYPTO_LAYER "CryptoObject"
static int crypto_layer(const obs_scene *scene, const obs_image *ids, obs_image *out,
                        const char *attrs[9], char **store)
{
    static char keys[4][64];
    char key[9];
    snprintf(key, sizeof key, "%08x", (unsigned)obs_murmur3_32(CRYPTO_LAYER, strlen(CRYPTO_LAYER), 0));
    key[7] = '\0';
    static const char *const field[4] = {"name", "hash", "conversion", "manifest"};
    for (int k = 0; k < 4; k++)
        snprintf(keys[k], sizeof keys[k], "cryptomatte/%s/%s", key, field[k]);
    cJSON *man = cJSON_CreateObject();
    size_t n = (size_t)ids->width * ids->height;
    if (!man || !(out->data = calloc(n * 4, sizeof(float)))) {
        cJSON_Delete(man);
        return -1;
    }
    out->width = ids->width;
    out->height = ids->height;
    out->channels = 4;
    for (size_t m = 0; m < scene->mesh_count; m++) {
        const obs_scene_mesh *sm = &scene->meshes[m];
        const char *name = sm->node && *sm->node ? sm->node : sm->name ? sm->name : "";
        char hex[9];
        snprintf(hex, sizeof hex, "%08x", (unsigned)obs_crypto_name_id(name));
        if (!cJSON_GetObjectItemCaseSensitive(man, name))
            cJSON_AddStringToObject(man, name, hex);
    }
    for (size_t i = 0; i < n; i++) {
        size_t m = (size_t)ids->data[i];
        if (m < 1 || m > scene->mesh_count)
            continue;
        const obs_scene_mesh *sm = &scene->meshes[m - 1];
        uint32_t h = obs_crypto_name_id(sm->node && *sm->node ? sm->node : sm->name ? sm->name : "");
        memcpy(&out->data[4 * i], &h, sizeof h);
        out->data[4 * i + 1] = 1.0f;
    }
    *store = cJSON_PrintUnformatted(man);
    cJSON_Delete(man);
    if (!*store)
        return -1;
    const char *v[4] = {CRYPTO_LAYER, "MurmurHash3_32", "uint32_to_float32", *store};
    for (int k = 0; k < 4; k++) {
        attrs[2 * k] = keys[k];
        attrs[2 * k + 1] = v[k];
    }
    attrs[8] = NULL;
    return 0;
}

/* gbuffer --deep: the A-buffer (obs_raster_deep) as a deep EXR. */
static int write_deep(const ground_args *a, obs_ctx *ctx, const obs_scene *scene,
                      const obs_camera *cam, int w, int h, double t0)
{
    obs_deep_image d;
    float *ids = NULL;
    char err[OBS_ERR_LEN] = "";
    /* --ids: each sample's object as the per-sample channel id and a
     * Cryptomatte layer of one rank per sample (coverage 1: a sample is one
     * object's), what the object masks read at every deep sample (README:
     * Object masks) */
    obs_status s = obs_raster_deep_ids(ctx, scene, cam, w, h, &d, a->ids ? &ids : NULL, err);
    if (s != OBS_OK)
        return cli_input_fail(s, a->scene, err);
    double t_raster = cli_now_s() - t0;
    const uint64_t samples = d.offset[(size_t)w * h];
    obs_image sid = {.data = ids, .width = samples ? (int)samples : 1, .height = 1, .channels = 1};
    obs_image crypto = {0};
    const char *attrs[9] = {NULL};
    char *manifest = NULL;
    if (ids && crypto_layer(scene, &sid, &crypto, attrs, &manifest) != 0) {
        obs_deep_free(&d);
        free(ids);
        obs_image_free(&crypto);
        free(manifest);
        return cli_fail(OBS_NO_MEMORY, a->out, NULL);
    }
    const obs_deep_channel extra[] = {
        {"id", ids, 1},
        {CRYPTO_LAYER "00.R", crypto.data, 4},
        {CRYPTO_LAYER "00.G", crypto.data + 1, 4},
        {CRYPTO_LAYER "00.B", crypto.data + 2, 4},
        {CRYPTO_LAYER "00.A", crypto.data + 3, 4},
    };
    s = obs_deep_write_exr_extra(a->out, &d, extra, ids ? 5 : 0, ids ? attrs : NULL, err);
    free(ids);
    obs_image_free(&crypto);
    free(manifest);
    if (s != OBS_OK) {
        obs_deep_free(&d);
        return cli_fail(s, a->out, err);
    }
    for (size_t m = 0; a->ids && !a->quiet && m < scene->mesh_count; m++)
        fprintf(stderr, "obscura: info: id %zu: mesh '%s', node '%s'\n", m + 1,
                scene->meshes[m].name ? scene->meshes[m].name : "",
                scene->meshes[m].node ? scene->meshes[m].node : "");
    if (!a->quiet) {
        size_t npx = (size_t)w * h, covered = 0;
        uint64_t most = 0;
        for (size_t i = 0; i < npx; i++) {
            uint64_t n = d.offset[i + 1] - d.offset[i];
            covered += n > 0;
            most = n > most ? n : most;
        }
        obs_ctx_info ci;
        obs_ctx_get_info(ctx, &ci);
        fprintf(stderr, "obscura: info: wrote %s: %dx%d deep, %llu samples (%zu pixels covered, "
                        "at most %llu per pixel), %s, rasterised in %.2f s\n",
                a->out, w, h, (unsigned long long)d.offset[npx], covered,
                (unsigned long long)most, obs_backend_name(ci.backend), t_raster);
    }
    obs_deep_free(&d);
    return EXIT_OK;
}

/* The G-buffer's EXR: depth, normals (world and camera), positions, the
 * colour (its coverage alone without albedo) and the baked channels. */
static int write_gbuffer(const ground_args *a, const obs_scene *scene, const obs_raster *r,
                         const obs_image *baked, int has_baked, const obs_image *ids,
                         const obs_camera *cam, int w, int h, char err[OBS_ERR_LEN])
{
    static const char *const n_id[] = {"id"};
    static const char *const n_crypto[] = {CRYPTO_LAYER "00.R", CRYPTO_LAYER "00.G",
                                           CRYPTO_LAYER "00.B", CRYPTO_LAYER "00.A"};
    obs_image crypto = {0};
    const char *attrs[9] = {NULL};
    char *manifest = NULL;
    if (ids->data && crypto_layer(scene, ids, &crypto, attrs, &manifest) != 0) {
        obs_image_free(&crypto);
        free(manifest);
        return cli_fail(OBS_NO_MEMORY, a->out, NULL);
    }
    static const char *const n_baked[] = {"_AO", "_AO_SHORT", "_AO_LONG"};
    static const char *const n_z[] = {"Z"}, *const n_n[] = {"N.X", "N.Y", "N.Z"},
                             *const n_nc[] = {"Ncam.X", "Ncam.Y", "Ncam.Z"},
                             *const n_p[] = {"P.X", "P.Y", "P.Z"}, *const n_c[] = {"R", "G", "B", "A"},
                             *const n_a[] = {"A"};
    obs_image alpha = {0};
    if (!r->has_albedo) {
        size_t n = (size_t)w * h;
        if (!(alpha.data = malloc(n * sizeof(float))))
            return cli_fail(OBS_NO_MEMORY, a->out, NULL);
        alpha.width = w;
        alpha.height = h;
        alpha.channels = 1;
        for (size_t i = 0; i < n; i++)
            alpha.data[i] = r->color.data[4 * i + 3];
    }
    const obs_exr_layer layers[] = {{&r->depth, n_z},       {&r->normal, n_n},
                                    {&r->normal_cam, n_nc}, {&r->position, n_p},
                                    r->has_albedo ? (obs_exr_layer){&r->color, n_c}
                                                  : (obs_exr_layer){&alpha, n_a},
                                    has_baked ? (obs_exr_layer){baked, n_baked}
                                              : (obs_exr_layer){ids, n_id},
                                    has_baked ? (obs_exr_layer){ids, n_id}
                                              : (obs_exr_layer){&crypto, n_crypto},
                                    {&crypto, n_crypto}};
    int nl = 5 + has_baked + 2 * (ids->data != NULL);
    /* Float: the sky depth (1e10) and world positions do not fit a half
     * (and a Cryptomatte ID is a float's bits). */
    obs_provenance prov = {.attrs = ids->data ? attrs : NULL};
    obs_exr_options o = {.pixel = OBS_EXR_FLOAT, .cam = cam, .prov = &prov};
    obs_status s = obs_exr_write_ex(a->out, layers, nl, &o, err);
    obs_image_free(&crypto);
    free(manifest);
    obs_image_free(&alpha);
    return s == OBS_OK ? EXIT_OK : cli_fail(s, a->out, err);
}

int cli_gbuffer(int argc, char **argv)
{
    ground_args a = {.cmd = "gbuffer"};
    parse(&a, argc, argv, 0);
    if (!ends_with(a.out, ".exr"))
        cli_die_usage(a.cmd, "%s: the G-buffer is written as .exr", a.out);

    obs_camera cam;
    obs_scene scene = {0};
    obs_raster r = {0};
    obs_ctx *ctx = NULL;
    obs_image baked = {0}, ids = {0};
    obs_dyn_model model = {0};
    char err[OBS_ERR_LEN] = "";
    int w, h, rc;
    size_t dyn_pixels = 0;
    obs_status s;
    if ((rc = load_camera(&a, &cam, &w, &h)) != EXIT_OK)
        return rc;
    if (a.dynamic && (s = obs_dyn_model_read(a.dynamic, &model, err)) != OBS_OK)
        return cli_input_fail(s, a.dynamic, err);
    if ((rc = load_scene(&a, &scene)) != EXIT_OK) {
        obs_dyn_model_free(&model);
        return rc;
    }
    if (a.dynamic && !model.level.triangles)
        fprintf(stderr, "obscura: warning: %s records no level: cannot check that it was baked "
                        "from %s\n", a.dynamic, a.scene);
    else if (a.dynamic && (s = obs_scene_check_dynamic_level(&scene, &model, err)) != OBS_OK) {
        rc = cli_input_fail(s, a.dynamic, err);
        goto done;
    }

    obs_ctx_desc desc = {.log = log_cb, .log_user = &a};
    const char *bname = a.backend ? a.backend : getenv("OBSCURA_BACKEND");
    if (bname && !strcmp(bname, "cpu")) {
        if (a.backend)
            cli_die_usage(a.cmd, "--backend cpu: %s rasterises a mesh, which needs a GL context "
                                 "(auto|egl-device|egl-surfaceless|osmesa); the CPU device runs "
                                 "the AO chain only", a.cmd);
        bname = NULL; /* OBSCURA_BACKEND=cpu names the AO chain's device: a GL context rasterises */
    }
    if (bname && *bname && obs_backend_parse(bname, &desc.backend) != OBS_OK)
        cli_die_usage(a.cmd, "backend '%s' is not one of auto|egl-device|egl-surfaceless|osmesa", bname);
    double t0 = cli_now_s();
    if ((s = obs_ctx_create(&desc, &ctx, err)) != OBS_OK) {
        rc = cli_fail(s, "OpenGL", err);
        goto done;
    }
    if (a.deep) {
        rc = write_deep(&a, ctx, &scene, &cam, w, h, t0);
        goto done;
    }
    if ((s = obs_raster_gbuffer(ctx, &scene, &cam, w, h, &r, err)) != OBS_OK) {
        rc = cli_input_fail(s, a.scene, err);
        goto done;
    }
    if (scene.baked && !a.dynamic &&
        (s = obs_raster_baked(ctx, &scene, &cam, w, h, &baked, err)) != OBS_OK) {
        rc = cli_input_fail(s, a.scene, err);
        goto done;
    }
    if (a.dynamic && (s = obs_raster_baked_dynamic(ctx, &scene, &cam, w, h, &r, &model,
                                                   !a.dynamic_linear, &baked, &dyn_pixels,
                                                   err)) != OBS_OK) {
        rc = cli_input_fail(s, a.scene, err);
        goto done;
    }
    /* _AO alone unless every primitive has the two distances */
    if (scene.baked && scene.baked_mask != 7) {
        for (size_t i = 0; i < (size_t)w * h; i++)
            baked.data[i] = baked.data[3 * i];
        baked.channels = 1;
    }
    if (a.ids && (s = obs_raster_ids(ctx, &scene, &cam, w, h, &ids, err)) != OBS_OK) {
        rc = cli_input_fail(s, a.scene, err);
        goto done;
    }
    double t_raster = cli_now_s() - t0;

    if ((rc = write_gbuffer(&a, &scene, &r, &baked, scene.baked != NULL, &ids, &cam, w, h, err)) != EXIT_OK)
        goto done;
    for (size_t m = 0; a.ids && !a.quiet && m < scene.mesh_count; m++)
        fprintf(stderr, "obscura: info: id %zu: mesh '%s', node '%s'\n", m + 1,
                scene.meshes[m].name ? scene.meshes[m].name : "",
                scene.meshes[m].node ? scene.meshes[m].node : "");
    if (!a.quiet) {
        obs_ctx_info ci;
        obs_ctx_get_info(ctx, &ci);
        fprintf(stderr, "obscura: info: wrote %s: %dx%d, %s, rasterised in %.2f s\n", a.out, w, h,
                obs_backend_name(ci.backend), t_raster);
        if (a.dynamic)
            fprintf(stderr, "obscura: info: %zu pixels of dynamic objects valued from the region "
                            "model %s\n", dyn_pixels, a.dynamic);
    }

done:
    obs_image_free(&baked);
    obs_image_free(&ids);
    obs_raster_free(&r);
    obs_ctx_destroy(ctx);
    obs_scene_free(&scene);
    obs_dyn_model_free(&model);
    return rc;
}

/* ---- obscura reference ----------------------------------------------------- */

static void progress_cb(void *user, int done, int total)
{
    int *last = user;
    int pct = (int)(100.0 * done / total);
    if (pct != *last) {
        *last = pct;
        fprintf(stderr, "\robscura: reference: %3d%% (%d/%d rows)", pct, done, total);
        if (done == total)
            fputc('\n', stderr);
    }
}

/* Reads the first channel triple of `cands` (each 3 names) that the file
 * has into one 3-channel image. */
static obs_status read_triple(const char *path, const char *const cands[][3], int ncand,
                              obs_image *out, char err[OBS_ERR_LEN])
{
    obs_status s = OBS_MISSING_CHANNEL;
    for (int c = 0; c < ncand; c++) {
        obs_image ch[3] = {{0}};
        s = OBS_OK;
        for (int k = 0; k < 3 && s == OBS_OK; k++)
            s = obs_exr_read_channel(path, cands[c][k], NULL, &ch[k], err);
        if (s == OBS_OK) {
            size_t n = (size_t)ch[0].width * ch[0].height;
            out->width = ch[0].width;
            out->height = ch[0].height;
            out->channels = 3;
            out->data = malloc(n * 3 * sizeof(float));
            if (!out->data)
                s = OBS_NO_MEMORY;
            for (size_t i = 0; out->data && i < n; i++)
                for (int k = 0; k < 3; k++)
                    out->data[3 * i + k] = ch[k].data[i];
        }
        for (int k = 0; k < 3; k++)
            obs_image_free(&ch[k]);
        if (s == OBS_OK)
            return OBS_OK;
    }
    snprintf(err, OBS_ERR_LEN, "no %s channels (looked for %s/%s/%s%s%s)", cands[0][0],
             cands[0][0], cands[0][1], cands[0][2], ncand > 1 ? " and " : "",
             ncand > 1 ? cands[1][0] : "");
    return s == OBS_NO_MEMORY ? s : OBS_MISSING_CHANNEL;
}

/* The points of a G-buffer: ours (P, N) or Blender's; the camera from
 * its header unless --camera gave one. */
static int read_gbuffer_points(const ground_args *a, obs_camera *cam, obs_image *pos,
                               obs_image *nrm, char err[OBS_ERR_LEN])
{
    static const char *const pos_cands[][3] = {{"P.X", "P.Y", "P.Z"},
                                               {"ViewLayer.Position.X", "ViewLayer.Position.Y",
                                                "ViewLayer.Position.Z"}};
    static const char *const nrm_cands[][3] = {{"N.X", "N.Y", "N.Z"},
                                               {"ViewLayer.Normal.X", "ViewLayer.Normal.Y",
                                                "ViewLayer.Normal.Z"}};
    obs_status s;
    if (!a->camera) {
        obs_gbuffer_file gf = {0};
        if ((s = obs_gbuffer_read_exr(a->gbuffer, NULL, NULL, &gf, err)) != OBS_OK)
            return cli_input_fail(s, a->gbuffer, err);
        *cam = gf.gb.camera;
        obs_gbuffer_free(&gf);
        if (!cam->has_projection)
            return cli_input_fail(OBS_NO_CAMERA, a->gbuffer,
                        "no worldToCamera/worldToNDC in the header: use --camera");
    }
    if ((s = read_triple(a->gbuffer, pos_cands, 2, pos, err)) != OBS_OK ||
        (s = read_triple(a->gbuffer, nrm_cands, 2, nrm, err)) != OBS_OK)
        return cli_input_fail(s, a->gbuffer, err);
    return EXIT_OK;
}

/* --obscurance: the bake's two distances, blend and decorators instead
 * of one distance. */
static int setup_obscurance(const ground_args *a, const obs_bake_params *bp,
                            const obs_scene *scene, obs_reference_desc *desc,
                            obs_bake_occluders **occl)
{
    desc->obscurance = 1;
    desc->obscurance_distance[0] = bp->distance_short;
    desc->obscurance_distance[1] = bp->distance_long;
    desc->blend = bp->blend;
    desc->obscurance_near = (float)a->near;
    if (scene->opacity && !a->quiet)
        fprintf(stderr, "obscura: info: %s: opacities not used: the obscurance traces every "
                        "surface as opaque, as the bake does\n", a->scene);
    int rc = load_occluders(a, occl);
    desc->occluders = *occl;
    return rc;
}

/* The PNG (the blend alone: channel 0 of 3 or 5 with obscurance) or the
 * EXR with the depth. */
static obs_status write_reference(const ground_args *a, int png, obs_image *ao,
                                  const obs_image *depth, const obs_camera *cam,
                                  char err[OBS_ERR_LEN])
{
    if (png) {
        if (a->obscurance) {
            size_t n = (size_t)ao->width * ao->height;
            for (size_t i = 0; i < n; i++)
                ao->data[i] = ao->data[(size_t)ao->channels * i];
            ao->channels = 1;
        }
        return obs_png_write(a->out, ao, 8, 0, err);
    }
    static const char *const n_obs[] = {"AO.Y", "AO_SHORT.Y", "AO_LONG.Y", "AO_NEAR.Y",
                                        "AO_BOTH.Y"},
                             *const n_ao[] = {"AO.Y"}, *const n_z[] = {"Z"};
    const obs_exr_layer layers[] = {{ao, a->obscurance ? n_obs : n_ao}, {depth, n_z}};
    return obs_exr_write(a->out, layers, 2, OBS_EXR_FLOAT, cam, err);
}

int cli_reference(int argc, char **argv)
{
    ground_args a = {.cmd = "reference", .distance = 0.5};
    parse(&a, argc, argv, 1);
    int png = ends_with(a.out, ".png");
    if (!png && !ends_with(a.out, ".exr"))
        cli_die_usage(a.cmd, "%s: the reference is written as .exr or .png", a.out);

    obs_camera cam = {0};
    obs_scene scene = {0};
    obs_bake_occluders *occl = NULL;
    obs_image pos = {0}, nrm = {0}, ao = {0}, depth = {0};
    char err[OBS_ERR_LEN] = "";
    int w = 0, h = 0, rc = EXIT_OK;
    obs_status s;

    if (a.camera && (rc = load_camera(&a, &cam, &w, &h)) != EXIT_OK)
        return rc;
    if (a.gbuffer) {
        if ((rc = read_gbuffer_points(&a, &cam, &pos, &nrm, err)) != EXIT_OK)
            goto done;
        w = pos.width;
        h = pos.height;
    }
    if ((rc = load_scene(&a, &scene)) != EXIT_OK)
        goto done;

    int last = -1;
    obs_reference_view view = {.camera = &cam, .width = w, .height = h,
                               .position = a.gbuffer ? &pos : NULL,
                               .normal = a.gbuffer ? &nrm : NULL};
    obs_reference_desc desc = {.distance = (float)a.distance, .spp = (int)a.spp,
                               .seed = a.seed, .threads = (int)a.threads};
    obs_bake_params bp;
    obs_bake_params_resolve(&a.bake, &bp);
    if (a.obscurance && (rc = setup_obscurance(&a, &bp, &scene, &desc, &occl)) != EXIT_OK)
        goto done;
    if (!a.quiet && isatty(STDERR_FILENO)) {
        desc.progress = progress_cb;
        desc.progress_user = &last;
    }
    double t0 = cli_now_s();
    if ((s = obs_reference_render(&scene, &view, &desc, &ao, &depth, err)) != OBS_OK) {
        rc = cli_input_fail(s, a.scene, err);
        goto done;
    }
    double t = cli_now_s() - t0;
    if ((s = write_reference(&a, png, &ao, &depth, &cam, err)) != OBS_OK) {
        rc = cli_fail(s, a.out, err);
        goto done;
    }
    if (!a.quiet && a.obscurance)
        fprintf(stderr, "obscura: info: wrote %s: %dx%d, obscurance %g,%g blend %g, %ld rays, "
                        "seed %llu, %.2f s\n",
                a.out, w, h, (double)bp.distance_short, (double)bp.distance_long,
                (double)bp.blend, a.spp ? a.spp : 256L, a.seed, t);
    else if (!a.quiet)
        fprintf(stderr, "obscura: info: wrote %s: %dx%d, distance %g, %ld spp, seed %llu, %.2f s\n",
                a.out, w, h, a.distance, a.spp ? a.spp : 256L, a.seed, t);

done:
    obs_bake_occluders_free(occl);
    obs_image_free(&ao);
    obs_image_free(&depth);
    obs_image_free(&pos);
    obs_image_free(&nrm);
    obs_scene_free(&scene);
    return rc;
}
