/* Channel maps: which EXR channels hold depth, normal and colour.
 * Presets know the names common renderers write; explicit names override
 * them.  Channels are matched by name only, never by position. */
#include <stdio.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

const char *const obs_channel_presets[] = {"auto",     "blender",   "generic", "arnold",
                                           "vray",     "renderman", "redshift", "karma",
                                           "mantra",   "octane",    "nuke",    NULL};

/* Blender's multilayer EXRs prefix every pass with the view layer. */
#define BLENDER_DEPTH_SUFFIX ".Depth.Z"
#define DEFAULT_BLENDER_LAYER "ViewLayer"


static int find(const char *const *names, int count, const char *name)
{
    for (int i = 0; i < count; i++)
        if (strcmp(names[i], name) == 0)
            return i;
    return -1;
}

/* Finds prefix+sfx[i] for i < n; all found -> 1 with out[] filled. */
static int find_set(const char *const *names, int count, const char *prefix,
                    const char *const *sfx, int n, int *out)
{
    char buf[512];
    int idx[4];
    for (int i = 0; i < n; i++) {
        if (snprintf(buf, sizeof buf, "%s%s", prefix, sfx[i]) >= (int)sizeof buf)
            return 0;
        if ((idx[i] = find(names, count, buf)) < 0)
            return 0;
    }
    memcpy(out, idx, (size_t)n * sizeof(int));
    return 1;
}

static void clear_match(obs__channel_match *m)
{
    m->depth = -1;
    for (int i = 0; i < 3; i++)
        m->normal[i] = -1;
    for (int i = 0; i < 4; i++)
        m->color[i] = -1;
    for (int i = 0; i < 3; i++)
        m->position[i] = -1;
    m->preset = "explicit";
    m->depth_mode = OBS_DEPTH_DEFAULT;
    m->normal_space = OBS_NORMALS_DEFAULT;
}

static const char *const XYZ[] = {".X", ".Y", ".Z"};
static const char *const RGB[] = {".R", ".G", ".B"};

/* Which colour plane a map asks for: the beauty (the default: the
 * composite multiplies what the renderer shows, and the albedo when the
 * file has no beauty), the diffuse albedo, or channels by name. */
enum { COLOR_DEFAULT, COLOR_BEAUTY, COLOR_ALBEDO, COLOR_NAMES };

static int color_role(const obs_channel_map *map)
{
    int named = 0;
    for (int i = 0; i < 4; i++)
        named += map->color[i] && *map->color[i];
    if (named == 1 && map->color[0] && !strcmp(map->color[0], "beauty"))
        return COLOR_BEAUTY;
    if (named == 1 && map->color[0] && !strcmp(map->color[0], "albedo"))
        return COLOR_ALBEDO;
    return named ? COLOR_NAMES : COLOR_DEFAULT;
}

/* blender: <Layer>.Depth.Z, <Layer>.Normal.X/Y/Z, the beauty
 * <Layer>.Combined.R/G/B/A, the albedo <Layer>.DiffCol.R/G/B.  The layer
 * is the prefix of any channel ending in ".Depth.Z", Blender's default
 * layer first. */
static void preset_blender(const char *const *names, int count, int role, obs__channel_match *m)
{
    char layer[256] = "";
    size_t sl = strlen(BLENDER_DEPTH_SUFFIX);
    clear_match(m);
    m->preset = "blender";
    /* Blender's Depth.Z is planar, its Normal pass world space
     * (../shared/data/README.md, Blender manual "Render Passes"). */
    m->depth_mode = OBS_DEPTH_PLANAR;
    m->normal_space = OBS_NORMALS_WORLD;
    m->depth = find(names, count, DEFAULT_BLENDER_LAYER BLENDER_DEPTH_SUFFIX);
    if (m->depth >= 0)
        snprintf(layer, sizeof layer, "%s", DEFAULT_BLENDER_LAYER);
    for (int i = 0; m->depth < 0 && i < count; i++) {
        size_t n = strlen(names[i]);
        if (n > sl && n - sl < sizeof layer && strcmp(names[i] + n - sl, BLENDER_DEPTH_SUFFIX) == 0) {
            memcpy(layer, names[i], n - sl);
            layer[n - sl] = '\0';
            m->depth = i;
        }
    }
    if (m->depth < 0)
        return;
    char pre[300];
    snprintf(pre, sizeof pre, "%s.Normal", layer);
    find_set(names, count, pre, XYZ, 3, m->normal);
    snprintf(pre, sizeof pre, "%s.Combined", layer);
    if (role != COLOR_ALBEDO && find_set(names, count, pre, RGB, 3, m->color)) {
        snprintf(pre, sizeof pre, "%s.Combined.A", layer);
        m->color[3] = find(names, count, pre);
    }
    snprintf(pre, sizeof pre, "%s.DiffCol", layer);
    if (m->color[0] < 0 && role != COLOR_BEAUTY)
        find_set(names, count, pre, RGB, 3, m->color);
}

/* generic: Z (depth.Z, Depth.Z); N.X/Y/Z, N.R/G/B, normal.X/Y/Z,
 * Normal.X/Y/Z; R, G, B and optionally A. */
static void preset_generic(const char *const *names, int count, int role, obs__channel_match *m)
{
    static const char *const depths[] = {"Z", "depth.Z", "Depth.Z"};
    static const char *const rgb[] = {"R", "G", "B"};
    clear_match(m);
    m->preset = "generic";
    for (int i = 0; i < 3 && m->depth < 0; i++)
        m->depth = find(names, count, depths[i]);
    if (!find_set(names, count, "N", XYZ, 3, m->normal) &&
        !find_set(names, count, "N", RGB, 3, m->normal) &&
        !find_set(names, count, "normal", XYZ, 3, m->normal))
        find_set(names, count, "Normal", XYZ, 3, m->normal);
    if (role != COLOR_ALBEDO && find_set(names, count, "", rgb, 3, m->color))
        m->color[3] = find(names, count, "A");
}

static const char *const XYZ_LOWER[] = {".x", ".y", ".z"};
static const char *const RGB_LOWER[] = {".r", ".g", ".b"};

/* The first of the colour prefixes `list` that is complete ("": bare
 * R,G,B), with its alpha. */
static void find_color(const char *const *names, int count, const char *const *list,
                       obs__channel_match *m)
{
    static const char *const bare[] = {"R", "G", "B"};
    for (const char *const *c = list; *c && m->color[0] < 0; c++) {
        char alpha[300];
        if (**c ? find_set(names, count, *c, RGB, 3, m->color)
                : find_set(names, count, "", bare, 3, m->color)) {
            snprintf(alpha, sizeof alpha, "%s%s", *c, **c ? ".A" : "A");
            m->color[3] = find(names, count, alpha);
        }
    }
}

/* A renderer's row of presets.c: its first depth name the file has, the
 * first normal and colour prefixes that are complete. */
static void preset_row(const char *const *names, int count, const obs__preset *pr, int role,
                       obs__channel_match *m)
{
    clear_match(m);
    m->preset = pr->name;
    m->depth_mode = pr->depth_mode;
    m->normal_space = pr->normal_space;
    for (const char *const *d = pr->depth; *d && m->depth < 0; d++)
        m->depth = find(names, count, *d);
    for (const char *const *n = pr->normal; *n && m->normal[0] < 0; n++)
        if (!find_set(names, count, *n, XYZ, 3, m->normal) &&
            !find_set(names, count, *n, RGB, 3, m->normal) &&
            !find_set(names, count, *n, XYZ_LOWER, 3, m->normal))
            find_set(names, count, *n, RGB_LOWER, 3, m->normal);
    if (role != COLOR_ALBEDO)
        find_color(names, count, pr->color, m);
    if (role != COLOR_BEAUTY)
        find_color(names, count, pr->albedo, m);
}

static int in_set(int idx, const int *set, int n)
{
    for (int i = 0; idx >= 0 && i < n; i++)
        if (set[i] == idx)
            return 1;
    return 0;
}

/* A world-space position pass, to solve or check the camera with:
 * Blender's <Layer>.Position (the depth's layer), else P, Position,
 * position, Pworld, worldPosition (.X/Y/Z or .R/G/B); none that reuses a
 * channel of the other planes. */
static void find_position(const char *const *names, int count, obs__channel_match *m,
                          const int used[8])
{
    static const char *const prefixes[] = {"P", "Position", "position", "Pworld", "worldPosition",
                                           NULL};
    size_t sl = strlen(BLENDER_DEPTH_SUFFIX), n = strlen(names[m->depth]);
    char pre[300];
    if (n > sl && n - sl < 256 && strcmp(names[m->depth] + n - sl, BLENDER_DEPTH_SUFFIX) == 0) {
        snprintf(pre, sizeof pre, "%.*s.Position", (int)(n - sl), names[m->depth]);
        find_set(names, count, pre, XYZ, 3, m->position);
    }
    for (const char *const *p = prefixes; *p && m->position[0] < 0; p++)
        if (!find_set(names, count, *p, XYZ, 3, m->position))
            find_set(names, count, *p, RGB, 3, m->position);
    for (int i = 0; i < 3; i++)
        if (in_set(m->position[i], used, 8))
            m->position[0] = m->position[1] = m->position[2] = -1;
}

/* "A, B, C", cut short with "... (N channels)". */
void obs__list_names(const char *const *names, int count, char *buf, size_t len)
{
    size_t at = 0;
    buf[0] = '\0';
    if (count == 0) {
        snprintf(buf, len, "no channels");
        return;
    }
    for (int i = 0; i < count; i++) {
        size_t n = strlen(names[i]) + (i ? 2 : 0);
        if (at + n > OBS__LIST_CHARS) {
            snprintf(buf + at, len - at, "%s... (%d channels)", i ? ", " : "", count);
            return;
        }
        at += (size_t)snprintf(buf + at, len - at, "%s%s", i ? ", " : "", names[i]);
    }
}

static obs_status missing(char err[OBS_ERR_LEN], const char *const *names, int count,
                          const char *what)
{
    char list[OBS__LIST_CHARS + 32];
    obs__list_names(names, count, list, sizeof list);
    return obs__fail(err, OBS_MISSING_CHANNEL, "%s; the file has: %s", what, list);
}

/* Looks up one explicitly named channel; a name the file lacks is an
 * error, since the caller asked for it. */
static obs_status explicit_channel(const char *const *names, int count, const char *name,
                                   const char *plane, int *idx, char err[OBS_ERR_LEN])
{
    char what[320];
    if ((*idx = find(names, count, name)) >= 0)
        return OBS_OK;
    snprintf(what, sizeof what, "%s channel '%.256s' not found", plane, name);
    return missing(err, names, count, what);
}


static int count_set(const char *const *v, int n)
{
    int k = 0;
    for (int i = 0; i < n; i++)
        k += v[i] && *v[i];
    return k;
}

obs_status obs__channel_map_resolve(const obs_channel_map *map,
                                    const char *const *names, int count,
                                    obs__channel_match *m,
                                    char err[OBS_ERR_LEN])
{
    return obs__channel_map_resolve_for(map, NULL, names, count, m, err);
}

obs_status obs__channel_map_resolve_for(const obs_channel_map *map, const char *detected,
                                        const char *const *names, int count,
                                        obs__channel_match *m, char err[OBS_ERR_LEN])
{
    static const obs_channel_map automap = {0};
    obs__channel_match cand[3];
    int ncand = 0, pick = -1;
    obs_status st;

    if (!map)
        map = &automap;
    const char *preset = map->preset && *map->preset ? map->preset : "auto";
    int is_auto = strcmp(preset, "auto") == 0;
    const obs__preset *row = obs__preset_find(is_auto ? detected : preset);
    int role = color_role(map);
    if (row)
        preset_row(names, count, row, role, &cand[ncand++]);
    if (is_auto || strcmp(preset, "blender") == 0)
        preset_blender(names, count, role, &cand[ncand++]);
    if (is_auto || strcmp(preset, "generic") == 0)
        preset_generic(names, count, role, &cand[ncand++]);
    if (ncand == 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "unknown channel preset '%.64s' (valid: auto, blender, generic, arnold, "
                         "vray, renderman, redshift, karma, mantra, octane, nuke)", preset);
    int nd = count_set(&map->depth, 1), nn = count_set(map->normal, 3);
    int nc = role == COLOR_NAMES ? count_set(map->color, 3) : 0;
    if (nn != 0 && nn != 3)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "explicit normal needs three channel names (X, Y, Z)");
    if (role == COLOR_NAMES && nc != 3)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "explicit colour needs three channel names "
                         "(R, G, B) and an optional alpha, or beauty or albedo");

    /* The first preset that finds its depth wins; with an explicit depth,
     * the first that finds anything supplies the other planes. */
    for (int i = 0; i < ncand && pick < 0; i++)
        if (cand[i].depth >= 0)
            pick = i;
    for (int i = 0; i < ncand && pick < 0 && nd; i++)
        if (cand[i].normal[0] >= 0 || cand[i].color[0] >= 0)
            pick = i;
    if (pick >= 0)
        *m = cand[pick];
    else
        clear_match(m); /* preset "explicit" */

    if (nd && (st = explicit_channel(names, count, map->depth, "depth", &m->depth, err)) != OBS_OK)
        return st;
    for (int i = 0; nn == 3 && i < 3; i++)
        if ((st = explicit_channel(names, count, map->normal[i], "normal", &m->normal[i], err)) != OBS_OK)
            return st;
    if (nc == 3) {
        for (int i = 0; i < 3; i++)
            if ((st = explicit_channel(names, count, map->color[i], "colour", &m->color[i], err)) != OBS_OK)
                return st;
        m->color[3] = -1;
        if (map->color[3] && *map->color[3] &&
            (st = explicit_channel(names, count, map->color[3], "alpha", &m->color[3], err)) != OBS_OK)
            return st;
    }
    if (m->depth < 0 && find(names, count, "VRayZDepth") + find(names, count, "VRayZDepth.R") +
                                find(names, count, "VRayZDepth.Z") > -3)
        return missing(err, names, count,
                       "no depth channel: VRayZDepth holds depth normalized between the render "
                       "element's zdepth min and max (white near), which the file does not record; "
                       "render V-Ray's raw Z-depth (a Z channel), or name a planar depth "
                       "channel with --depth");
    if (m->depth < 0 && row && !is_auto) {
        char what[320];
        snprintf(what, sizeof what, "no depth channel: looked for %s's %s%s%s", row->name,
                 row->depth[0], row->depth[1] ? ", " : "", row->depth[1] ? row->depth[1] : "");
        return missing(err, names, count, what);
    }
    if (m->depth < 0)
        return missing(err, names, count,
                       is_auto ? "no depth channel: looked for '<layer>.Depth.Z' (blender) "
                                 "and Z, depth.Z, Depth.Z (generic)"
                       : strcmp(preset, "blender") == 0
                           ? "no depth channel: looked for '<layer>.Depth.Z' (blender, "
                             "e.g. ViewLayer.Depth.Z)"
                           : "no depth channel: looked for Z, depth.Z, Depth.Z (generic)");

    if ((role == COLOR_BEAUTY || role == COLOR_ALBEDO) && m->color[0] < 0)
        return missing(err, names, count, role == COLOR_BEAUTY
                           ? "--color beauty: no beauty channels (Blender's <layer>.Combined, "
                             "R,G,B[,A], or the preset's beauty layer)"
                           : "--color albedo: no albedo channels (Blender's <layer>.DiffCol, "
                             "or the preset's albedo layer); name them with --color R,G,B");
    /* A preset's plane that reuses an explicitly named channel gives way;
     * explicit names that clash among themselves are an error, since one
     * EXR channel decodes into one place. */
    int ex[8], nex = 0;
    if (nd)
        ex[nex++] = m->depth;
    for (int i = 0; nn == 3 && i < 3; i++)
        ex[nex++] = m->normal[i];
    for (int i = 0; nc == 3 && i < 4; i++)
        if (m->color[i] >= 0)
            ex[nex++] = m->color[i];
    if (nn != 3 && (in_set(m->normal[0], ex, nex) || in_set(m->normal[1], ex, nex) ||
                    in_set(m->normal[2], ex, nex)))
        m->normal[0] = m->normal[1] = m->normal[2] = -1;
    if (nc != 3 && (in_set(m->color[0], ex, nex) || in_set(m->color[1], ex, nex) ||
                    in_set(m->color[2], ex, nex)))
        m->color[0] = m->color[1] = m->color[2] = m->color[3] = -1;
    if (nc != 3 && in_set(m->color[3], ex, nex))
        m->color[3] = -1;
    int idx[8] = {m->depth, m->normal[0], m->normal[1], m->normal[2],
                  m->color[0], m->color[1], m->color[2], m->color[3]};
    for (int i = 0; i < 8; i++)
        if (idx[i] >= 0 && in_set(idx[i], idx + i + 1, 7 - i))
            return obs__fail(err, OBS_INVALID_ARGUMENT, "channel '%.256s' is mapped twice",
                             names[idx[i]]);
    find_position(names, count, m, idx);
    return OBS_OK;
}
