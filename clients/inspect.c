/* obscura inspect FILE [--json] [reading options]: what obscura reads from
 * an EXR and why: the renderer its header names, each plane's channel and
 * the preset that mapped it, the camera and the attributes it came from
 * with their cross-check, the depth and normal conventions, the windows,
 * the part, the position pass (and the camera solved from it when the file
 * has none), and the sanity warnings.  Reads the file the way `obscura ao`
 * does (same flags for the channel map and the conventions). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "cli.h"
#include "flags.h"
#include "inspect.h"
#include "obscura/deep.h"
#include "obscura/io.h"
#include "obscura/mask.h"

static const char *depth_name(int m)
{
    static const char *const names[] = {"(not known: planar)", "planar", "radial", "ndc",
                                        "inverse", "normalized"};
    return m >= 0 && m < (int)(sizeof names / sizeof names[0]) ? names[m] : "?";
}

static const char *space_name(int s)
{
    return s == OBS_NORMALS_CAMERA ? "camera" : s == OBS_NORMALS_WORLD ? "world" : "(not known: world)";
}

static void add_matrix(cJSON *o, const char *name, const float m[16])
{
    double v[16];
    for (int i = 0; i < 16; i++)
        v[i] = m[i];
    cJSON_AddItemToObject(o, name, cJSON_CreateDoubleArray(v, 16));
}

static void print_matrix(const char *name, const float m[16])
{
    printf("  %s:\n", name);
    for (int r = 0; r < 4; r++)
        printf("    %10.5g %10.5g %10.5g %10.5g\n", m[r * 4], m[r * 4 + 1], m[r * 4 + 2],
               m[r * 4 + 3]);
}

static char **part_lines; /* obs_exr_describe_parts() of the file */
/* The geometry's depth as the chain reads it (obs_gbuffer_depth_range)
 * and the radius a user would start from (obs_radius_suggest: a tenth of
 * the median depth, README.md "Warnings"). */
static obs_depth_range range;
/* The Cryptomatte layers and ID channels (obs_crypto_describe): what the
 * object-mask selectors can name. */
static obs_crypto_info crypto;

static void json_masks(cJSON *o)
{
    cJSON *layers = cJSON_AddArrayToObject(o, "cryptomatte"), *ids;
    for (int i = 0; i < crypto.layer_count; i++) {
        const obs_crypto_layer *L = &crypto.layers[i];
        cJSON *l = cJSON_CreateObject(), *names = cJSON_CreateArray();
        cJSON_AddItemToArray(layers, l);
        cJSON_AddStringToObject(l, "name", L->name);
        cJSON_AddStringToObject(l, "key", L->key);
        cJSON_AddStringToObject(l, "hash", L->hash);
        cJSON_AddNumberToObject(l, "ranks", 2 * L->rank_sets);
        cJSON_AddStringToObject(l, "manifest", L->manif_file[0] ? L->manif_file : "header");
        cJSON_AddStringToObject(l, "manifest_error", L->manifest_error);
        for (int k = 0; k < L->entry_count; k++) {
            char hex[9];
            cJSON *e = cJSON_CreateObject();
            snprintf(hex, sizeof hex, "%08x", L->ids[k]);
            cJSON_AddStringToObject(e, "name", L->names[k]);
            cJSON_AddStringToObject(e, "id", hex);
            cJSON_AddItemToArray(names, e);
        }
        cJSON_AddItemToObject(l, "names", names);
    }
    ids = cJSON_AddArrayToObject(o, "id_channels");
    for (int i = 0; i < crypto.id_count; i++)
        cJSON_AddItemToArray(ids, cJSON_CreateString(crypto.id_channels[i]));
}

static void print_masks(void)
{
    if (!crypto.layer_count && !crypto.id_count) {
        printf("  object masks: no Cryptomatte layer, no ID channel (matte:CHANNEL still works)\n");
        return;
    }
    printf("  object masks (--receivers, --occluders, --self-only):\n");
    for (int i = 0; i < crypto.layer_count; i++) {
        const obs_crypto_layer *L = &crypto.layers[i];
        printf("    Cryptomatte layer %s (key %s, %d ranks, manifest %s%s): %d names\n", L->name,
               L->key, 2 * L->rank_sets, L->manif_file[0] ? "in " : "in the header",
               L->manif_file, L->entry_count);
        if (L->manifest_error[0])
            printf("      error: %s\n", L->manifest_error);
        for (int k = 0; k < L->entry_count; k++)
            printf("      %08x  %s\n", L->ids[k], L->names[k]);
    }
    for (int i = 0; i < crypto.id_count; i++)
        printf("    ID channel %s (id:%s=N)\n", crypto.id_channels[i], crypto.id_channels[i]);
}

static int print_json(const char *path, const obs_gbuffer *gb, const obs_exr_info *info)
{
    cJSON *o = cJSON_CreateObject(), *ch = cJSON_CreateObject(), *cam = cJSON_CreateObject();
    cJSON *w = cJSON_CreateArray();
    cJSON_AddStringToObject(o, "file", path);
    cJSON_AddStringToObject(o, "renderer", info->renderer);
    cJSON_AddStringToObject(o, "renderer_from", info->renderer_why);
    cJSON_AddStringToObject(o, "preset", info->preset);
    cJSON_AddStringToObject(ch, "depth", info->depth);
    const char *n[3] = {info->normal[0], info->normal[1], info->normal[2]};
    const char *c[4] = {info->color[0], info->color[1], info->color[2], info->color[3]};
    cJSON_AddItemToObject(ch, "normal", info->normal[0][0] ? cJSON_CreateStringArray(n, 3) : cJSON_CreateNull());
    cJSON_AddItemToObject(ch, "color", info->color[0][0] ? cJSON_CreateStringArray(c, info->color[3][0] ? 4 : 3)
                                                         : cJSON_CreateNull());
    const char *p[3] = {info->position[0], info->position[1], info->position[2]};
    cJSON_AddItemToObject(ch, "position", info->position[0][0] ? cJSON_CreateStringArray(p, 3)
                                                               : cJSON_CreateNull());
    cJSON_AddItemToObject(o, "channels", ch);
    cJSON_AddStringToObject(o, "depth_mode", info->depth_mode ? depth_name(info->depth_mode) : "");
    cJSON_AddStringToObject(o, "normal_space",
                            info->normal_space ? space_name(info->normal_space) : "");
    cJSON_AddStringToObject(cam, "source", info->camera_source);
    cJSON_AddStringToObject(cam, "check", info->camera_check);
    cJSON_AddStringToObject(cam, "clip", info->camera_clip);
    cJSON_AddBoolToObject(cam, "arnold_ndc", info->camera_arnold);
    if (gb->camera.has_world_to_camera)
        add_matrix(cam, "world_to_camera", gb->camera.world_to_camera);
    if (gb->camera.has_projection)
        add_matrix(cam, "projection", gb->camera.projection);
    cJSON_AddItemToObject(o, "camera", cam);
    cJSON *dr = cJSON_CreateObject();
    cJSON_AddNumberToObject(dr, "geometry_pixels", (double)range.geometry);
    cJSON_AddNumberToObject(dr, "min", range.min);
    cJSON_AddNumberToObject(dr, "median", range.median);
    cJSON_AddNumberToObject(dr, "max", range.max);
    cJSON_AddItemToObject(o, "depth_range", dr);
    cJSON_AddNumberToObject(o, "radius_suggested", obs_radius_suggest(&range));
    int dwin[4] = {gb->display_x, gb->display_y, gb->width, gb->height};
    int disp[2] = {gb->display_width ? gb->display_width : gb->width,
                   gb->display_height ? gb->display_height : gb->height};
    cJSON_AddItemToObject(o, "data_window", cJSON_CreateIntArray(dwin, 4));
    cJSON_AddItemToObject(o, "display_size", cJSON_CreateIntArray(disp, 2));
    cJSON_AddNumberToObject(o, "part", info->part);
    cJSON_AddNumberToObject(o, "parts", info->part_count);
    cJSON *pl = cJSON_CreateArray();
    for (char **l = part_lines; l && *l; l++)
        cJSON_AddItemToArray(pl, cJSON_CreateString(*l));
    cJSON_AddItemToObject(o, "part_list", pl);
    cJSON_AddStringToObject(o, "view", info->view);
    cJSON_AddNumberToObject(o, "parts_read", info->parts_read);
    cJSON_AddStringToObject(o, "compression", info->compression ? info->compression : "");
    cJSON_AddBoolToObject(o, "tiled", info->tiled);
    for (int i = 0; i < info->warning_count; i++)
        cJSON_AddItemToArray(w, cJSON_CreateString(info->warnings[i]));
    cJSON_AddItemToObject(o, "warnings", w);
    json_masks(o);
    char *s = cJSON_Print(o);
    int ok = s != NULL;
    if (s)
        printf("%s\n", s);
    free(s);
    cJSON_Delete(o);
    return ok ? EXIT_OK : EXIT_FAIL;
}

static void print_text(const char *path, const obs_gbuffer *gb, const obs_exr_info *info)
{
    printf("%s\n", path);
    printf("  renderer: %s%s%s%s\n", info->renderer[0] ? info->renderer : "(not named by the header)",
           info->renderer_why[0] ? " (from " : "", info->renderer_why, info->renderer_why[0] ? ")" : "");
    printf("  channels (preset %s):\n", info->preset);
    printf("    depth   %s\n", info->depth);
    if (info->normal[0][0])
        printf("    normal  %s, %s, %s\n", info->normal[0], info->normal[1], info->normal[2]);
    else
        printf("    normal  (none: derived from depth)\n");
    if (info->color[0][0])
        printf("    colour  %s, %s, %s%s%s\n", info->color[0], info->color[1], info->color[2],
               info->color[3][0] ? ", " : "", info->color[3]);
    else
        printf("    colour  (none)\n");
    if (info->position[0][0])
        printf("    position %s, %s, %s (world space: solves or checks the camera)\n",
               info->position[0], info->position[1], info->position[2]);
    printf("  depth: %s\n  normals: %s space\n", depth_name(info->depth_mode),
           space_name(info->normal_space));
    if (range.geometry > 0)
        printf("  depth range: %.4g..%.4g, median %.4g (over %ld geometry pixels)\n"
               "  radius to start from: %.3g (a tenth of the median depth)\n", range.min,
               range.max, range.median, range.geometry, obs_radius_suggest(&range));
    else
        printf("  depth range: no geometry pixel (every depth is background)\n");
    printf("  camera: %s\n", info->camera_source[0] ? info->camera_source : "(none in the header)");
    if (info->camera_check[0])
        printf("  camera check: %s\n", info->camera_check);
    printf("  clip range: %s\n", info->camera_clip[0] ? info->camera_clip : "0.1..1000 (default)");
    if (gb->camera.has_world_to_camera)
        print_matrix("world_to_camera (column vectors, -Z forward)", gb->camera.world_to_camera);
    if (gb->camera.has_projection)
        print_matrix("projection (OpenGL clip space)", gb->camera.projection);
    printf("  data window: %dx%d at (%d, %d) of a %dx%d display window\n", gb->width, gb->height,
           gb->display_x, gb->display_y, gb->display_width ? gb->display_width : gb->width,
           gb->display_height ? gb->display_height : gb->height);
    printf("  part %d of %d, %s, %s\n", info->part, info->part_count,
           info->tiled ? "tiled" : "scanline", info->compression ? info->compression : "?");
    if (info->view[0])
        printf("  view: %s, channels gathered from %d part%s\n", info->view, info->parts_read,
               info->parts_read == 1 ? "" : "s");
    if (part_lines && part_lines[0] && part_lines[1])
        for (char **l = part_lines; *l; l++)
            printf("    part %s\n", *l);
    print_masks();
    for (int i = 0; i < info->warning_count; i++)
        printf("  warning: %s\n", info->warnings[i]);
    if (!info->warning_count)
        printf("  sanity: no warnings\n");
}

/* A request option or a parameter of the table (what changes how the
 * file is read): 1 when taken, 0 with a message in err. */
static int usable_flag(obs_http_request *req, int argc, char **argv, int *i, char err[OBS_ERR_LEN])
{
    const obs_http_option *op;
    int k = cli_request_flag(argc, argv, i, req, &op, err);
    if (k != 0)
        return k == 1;
    const char *arg = argv[*i], *eq = strchr(arg + 2, '=');
    char name[64];
    snprintf(name, sizeof name, "%.*s", (int)(eq ? (size_t)(eq - arg - 2) : strlen(arg + 2)), arg + 2);
    if (!obs_param_find(name)) {
        snprintf(err, OBS_ERR_LEN, "unknown option '%.200s'", arg);
        return 0;
    }
    if (!eq && *i + 1 >= argc) {
        snprintf(err, OBS_ERR_LEN, "parameter --%s needs a value", name);
        return 0;
    }
    return obs_param_set(&req->params, name, eq ? eq + 1 : argv[++*i], err) == OBS_OK;
}

static int cli_inspect_file(const char *in, int json, obs_http_request *req);

int cli_inspect(int argc, char **argv)
{
    obs_http_request req;
    char err[OBS_ERR_LEN] = "";
    const char *in = NULL;
    int json = 0;
    obs_http_request_init(&req);
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--json"))
            json = 1;
        else if (argv[i][0] != '-' && !in)
            in = argv[i];
        else if (argv[i][0] != '-' || argv[i][1] != '-' || !usable_flag(&req, argc, argv, &i, err)) {
            fprintf(stderr, "obscura: inspect: %s (usage: obscura inspect FILE [--json] "
                    "[--preset P] [--depth CH] [--normal X,Y,Z] [--color R,G,B[,A]] "
                    "[--depth-mode M] [--normal-space S] ...)\n",
                    err[0] ? err : "unknown argument");
            return EXIT_USAGE;
        }
    }
    if (!in) {
        fprintf(stderr, "obscura: inspect: no input file (usage: obscura inspect FILE [--json])\n");
        return EXIT_USAGE;
    }
    if (obs_exr_describe_parts(in, &part_lines, err) != OBS_OK) {
        fprintf(stderr, "obscura: %s\n", err);
        return EXIT_BADINPUT;
    }
    int rc = cli_inspect_file(in, json, &req);
    obs_strv_free(part_lines);
    part_lines = NULL;
    return rc;
}

static int inspect_file(const char *in, int json, obs_http_request *req);

/* inspect_file with the object masks described first; a file that is no
 * G-buffer (a Cryptomatte-only frame) still has its layers listed. */
static int cli_inspect_file(const char *in, int json, obs_http_request *req)
{
    char err[OBS_ERR_LEN] = "";
    if (obs_crypto_describe(in, NULL, 0, &crypto, err) != OBS_OK)
        memset(&crypto, 0, sizeof crypto);
    int rc = inspect_file(in, json, req);
    if (rc != EXIT_OK && (crypto.layer_count || crypto.id_count) && !json) {
        printf("%s (not read as a G-buffer)\n", in);
        print_masks();
    } else if (rc != EXIT_OK && (crypto.layer_count || crypto.id_count)) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "file", in);
        cJSON_AddBoolToObject(o, "gbuffer", 0);
        json_masks(o);
        char *s = cJSON_Print(o);
        if (s)
            printf("%s\n", s);
        free(s);
        cJSON_Delete(o);
    }
    obs_crypto_info_free(&crypto);
    return rc;
}

static int inspect_file(const char *in, int json, obs_http_request *req)
{
    obs_gbuffer_file gf = {0};
    char err[OBS_ERR_LEN] = "";
    int deep = 0;
    if (obs_exr_is_deep(in, &deep, err) == OBS_OK && deep) {
        obs_deep_image d = {0};
        if (obs_deep_read_exr(in, NULL, &d, err) != OBS_OK) {
            fprintf(stderr, "obscura: %s\n", err);
            return EXIT_BADINPUT;
        }
        /* the deep reader keeps only the camera: describe it as a flat
         * G-buffer with no planes */
        gf.gb.width = d.width;
        gf.gb.height = d.height;
        gf.gb.display_x = d.display_x;
        gf.gb.display_y = d.display_y;
        gf.gb.display_width = d.display_width;
        gf.gb.display_height = d.display_height;
        if (obs_exr_describe_camera(in, d.part, &gf.info, &gf.gb.camera, err) != OBS_OK) {
            fprintf(stderr, "obscura: %s\n", err);
            obs_deep_free(&d);
            return EXIT_BADINPUT;
        }
        snprintf(gf.info.preset, sizeof gf.info.preset, "deep");
        snprintf(gf.info.depth, sizeof gf.info.depth, "Z (deep samples)");
        if (d.has_normal)
            for (int k = 0; k < 3; k++)
                snprintf(gf.info.normal[k], sizeof gf.info.normal[k], "N.%c", "XYZ"[k]);
        gf.info.part = d.part;
        gf.info.part_count = 1;
        if (obs_deep_depth_range(&d, &range) != 0)
            memset(&range, 0, sizeof range);
        obs_deep_free(&d);
        int rc = json ? print_json(in, &gf.gb, &gf.info) : (print_text(in, &gf.gb, &gf.info), EXIT_OK);
        return rc;
    }
    if (obs_gbuffer_read_exr(in, &req->map, NULL, &gf, err) != OBS_OK) {
        fprintf(stderr, "obscura: %s\n", err);
        return EXIT_BADINPUT;
    }
    /* a file with a position pass and no camera: what the solver finds */
    if (gf.gb.position.data && obs_gbuffer_solve_camera(&gf, &req->params, err) != OBS_OK &&
        gf.info.warning_count < OBS_EXR_WARNINGS)
        snprintf(gf.info.warnings[gf.info.warning_count++], sizeof gf.info.warnings[0],
                 "the camera cannot be solved from the position pass: %.160s", err);
    obs_gbuffer_sanity(&gf.gb, &req->params, &gf.info);
    if (obs_gbuffer_depth_range(&gf.gb, &req->params, &range) != 0)
        memset(&range, 0, sizeof range);
    int rc = json ? print_json(in, &gf.gb, &gf.info) : (print_text(in, &gf.gb, &gf.info), EXIT_OK);
    obs_gbuffer_free(&gf);
    return rc;
}
