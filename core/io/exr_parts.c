/* Which parts of a multi-part EXR a G-buffer is read from: the part the
 * map names (--part NAME|INDEX), else the parts of one view (--view NAME;
 * by default the file's default view: the first of its multiView
 * attribute, else the view of part 0; OpenEXR "Storing Multi-View Images
 * in OpenEXR Files": the first view listed is the default), else every
 * part.  Parts of a view are read together: their channels are gathered
 * (the depth from one part, the colour from another). */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

const char *obs__exr_attr_string(exr_const_context_t ctx, int part, const char *name)
{
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_name(ctx, part, name, &a) != EXR_ERR_SUCCESS || !a ||
        a->type != EXR_ATTR_STRING || !a->string || !a->string->str)
        return NULL;
    return a->string->str;
}

/* The first entry of a multiView attribute in any part, or NULL. */
static const char *default_view(exr_const_context_t ctx, int parts, char *buf, size_t len)
{
    for (int p = 0; p < parts; p++) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_name(ctx, p, "multiView", &a) == EXR_ERR_SUCCESS && a &&
            a->type == EXR_ATTR_STRING_VECTOR && a->stringvector && a->stringvector->n_strings > 0 &&
            a->stringvector->strings[0].str) {
            snprintf(buf, len, "%s", a->stringvector->strings[0].str);
            return buf;
        }
    }
    return NULL;
}

/* "0 'rgba_right' (right), 1 ..." for messages. */
static void list_parts(exr_const_context_t ctx, int parts, char *buf, size_t len)
{
    size_t at = 0;
    buf[0] = '\0';
    for (int p = 0; p < parts && at + 80 < len; p++) {
        const char *n = obs__exr_attr_string(ctx, p, "name"),
                   *v = obs__exr_attr_string(ctx, p, "view");
        at += (size_t)snprintf(buf + at, len - at, "%s%d%s%.40s%s%s%.20s%s", p ? ", " : "", p,
                               n ? " '" : "", n ? n : "", n ? "'" : "", v ? " (" : "", v ? v : "",
                               v ? ")" : "");
    }
}

obs_status obs__exr_select_parts(exr_const_context_t ctx, int parts, const obs_channel_map *map,
                                 obs__part_set *s, char err[OBS_ERR_LEN])
{
    char list[OBS__LIST_CHARS + 64], dv[64];
    memset(s, 0, sizeof *s);
    if (!(s->part = malloc((size_t)parts * sizeof *s->part)))
        return obs__fail(err, OBS_NO_MEMORY, "a list of %d parts", parts);
    const char *want_part = map && map->part && *map->part ? map->part : NULL;
    const char *want_view = map && map->view && *map->view ? map->view : NULL;

    if (want_part) {
        int digits = 1, found = -1;
        for (const char *c = want_part; *c; c++)
            digits &= isdigit((unsigned char)*c) != 0;
        if (digits && strlen(want_part) < 10 && atoi(want_part) < parts)
            found = atoi(want_part);
        for (int p = 0; p < parts && found < 0; p++) {
            const char *n = obs__exr_attr_string(ctx, p, "name");
            if (n && strcmp(n, want_part) == 0)
                found = p;
        }
        obs__exr_msg_reset();
        if (found < 0) {
            list_parts(ctx, parts, list, sizeof list);
            obs__exr_msg_reset();
            return obs__fail(err, OBS_INVALID_ARGUMENT, "no part '%.64s' (by name or index); the "
                             "file's parts: %s", want_part, list);
        }
        s->part[s->count++] = found;
        snprintf(s->why, sizeof s->why, "part %d (--part)", found);
        return OBS_OK;
    }

    int any_view = 0;
    for (int p = 0; p < parts; p++)
        any_view |= obs__exr_attr_string(ctx, p, "view") != NULL;
    const char *view = want_view;
    if (!view && any_view) {
        view = default_view(ctx, parts, dv, sizeof dv);
        if (!view && obs__exr_attr_string(ctx, 0, "view")) {
            snprintf(dv, sizeof dv, "%s", obs__exr_attr_string(ctx, 0, "view"));
            view = dv;
        }
        snprintf(s->why, sizeof s->why, "the default view");
    }
    obs__exr_msg_reset();
    if (!view || (!any_view && parts == 1 && !want_view)) {
        for (int p = 0; p < parts; p++)
            s->part[s->count++] = p;
        return OBS_OK;
    }
    if (!any_view) {
        return obs__fail(err, OBS_INVALID_ARGUMENT, "--view '%.64s': the file's parts carry no "
                         "view attribute (a single-part multi-view file's other views are "
                         "channels prefixed with the view's name: name them with --depth, "
                         "--normal, --color)", view);
    }
    /* the view's parts first, then the parts of no view */
    for (int pass = 0; pass < 2; pass++)
        for (int p = 0; p < parts; p++) {
            const char *v = obs__exr_attr_string(ctx, p, "view");
            if (pass == 0 ? v && strcmp(v, view) == 0 : !v)
                s->part[s->count++] = p;
        }
    int of_view = 0;
    for (int i = 0; i < s->count; i++) {
        const char *v = obs__exr_attr_string(ctx, s->part[i], "view");
        of_view += v != NULL;
    }
    obs__exr_msg_reset();
    if (!of_view) {
        list_parts(ctx, parts, list, sizeof list);
        obs__exr_msg_reset();
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no part of view '%.64s'; the file's parts: %s",
                         view, list);
    }
    snprintf(s->view, sizeof s->view, "%s", view);
    if (want_view)
        snprintf(s->why, sizeof s->why, "--view");
    s->by_view = 1;
    return OBS_OK;
}

void obs__part_set_free(obs__part_set *s)
{
    free(s->part);
    memset(s, 0, sizeof *s);
}
