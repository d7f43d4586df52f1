/* What obscura inspect shows beside the G-buffer: the renderer and camera
 * of any EXR part (flat or deep) as the readers find them (exr_info.c),
 * and the list of parts with their names, views and channels. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

/* describe_camera's arguments and result. */
typedef struct camera_job {
    int part;
    obs_exr_info *info;
    obs_camera *cam;
} camera_job;

static obs_status camera_reader(exr_context_t ctx, int64_t size, void *user,
                                char why[OBS_ERR_LEN])
{
    const camera_job *j = user;
    obs_gbuffer gb;
    obs__channel_match m;
    (void)size;
    (void)why;
    memset(&gb, 0, sizeof gb);
    memset(&m, 0, sizeof m);
    obs__exr_describe(ctx, j->part, &m, &gb, j->info);
    obs__exr_msg_reset(); /* a missing attribute is not an error */
    *j->cam = gb.camera;
    return OBS_OK;
}

obs_status obs_exr_describe_camera(const char *path, int part, obs_exr_info *info,
                                   obs_camera *cam, char err[OBS_ERR_LEN])
{
    camera_job j = {part, info, cam};
    return obs__exr_read_with(path, path, NULL, camera_reader, &j, err);
}

/* One line a part into *(char ***)user (obs_exr_describe_parts). */
static obs_status parts_reader(exr_context_t ctx, int64_t size, void *user,
                               char why[OBS_ERR_LEN])
{
    int parts = 0;
    char **v = NULL;
    (void)size;
    if (exr_get_count(ctx, &parts) != EXR_ERR_SUCCESS || parts < 1 ||
        !(v = calloc((size_t)parts + 1, sizeof *v)))
        return obs__fail(why, parts < 1 ? OBS_BAD_FILE : OBS_NO_MEMORY, "part list");
    for (int p = 0; p < parts; p++) {
        const exr_attribute_t *n = NULL, *w = NULL;
        const exr_attr_chlist_t *cl = NULL;
        char buf[OBS__LIST_CHARS + 200], list[OBS__LIST_CHARS + 32] = "";
        const char *names[OBS__LIST_CHARS];
        int count = 0;
        exr_get_attribute_by_name(ctx, p, "name", &n);
        exr_get_attribute_by_name(ctx, p, "view", &w);
        if (exr_get_channels(ctx, p, &cl) == EXR_ERR_SUCCESS && cl)
            for (int i = 0; i < cl->num_channels && count < OBS__LIST_CHARS; i++)
                names[count++] = cl->entries[i].name.str ? cl->entries[i].name.str : "";
        obs__list_names(names, count, list, sizeof list);
        int named = n && n->type == EXR_ATTR_STRING && n->string && n->string->str;
        int viewed = w && w->type == EXR_ATTR_STRING && w->string && w->string->str;
        snprintf(buf, sizeof buf, "%d%s%.60s%s%s%.30s%s: %s", p, named ? " '" : "",
                 named ? n->string->str : "", named ? "'" : "", viewed ? " (view " : "",
                 viewed ? w->string->str : "", viewed ? ")" : "", list);
        if (!(v[p] = strdup(buf))) {
            obs_strv_free(v);
            return obs__fail(why, OBS_NO_MEMORY, "part list");
        }
    }
    obs__exr_msg_reset(); /* a missing attribute is not an error */
    *(char ***)user = v;
    return OBS_OK;
}

obs_status obs_exr_describe_parts(const char *path, char ***lines, char err[OBS_ERR_LEN])
{
    *lines = NULL;
    return obs__exr_read_with(path, path, NULL, parts_reader, lines, err);
}
