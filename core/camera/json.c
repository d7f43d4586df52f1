/* The camera JSON written beside a render (see
 * tests/data/room_small.camera.json); the camera maths is
 * core/camera/request.c. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "obscura/io.h"

/* A camera file is a few hundred bytes; anything near this is not one. */
#define MAX_JSON_BYTES (1 << 20)

/* Clip range of a camera JSON that gives a field of view but no near/far. */
#define DEFAULT_NEAR 0.1
#define DEFAULT_FAR 1000.0

/* Reads the whole file, NUL-terminated; caller frees *buf. */
static obs_status slurp(const char *path, char **buf, size_t *len, char err[OBS_ERR_LEN])
{
    FILE *fp = fopen(path, "rb");
    obs_status st = OBS_OK;
    *buf = NULL;
    if (!fp)
        return obs__fail(err, OBS_IO, "cannot open: %s", strerror(errno));
    if (!(*buf = malloc(MAX_JSON_BYTES + 1))) {
        st = obs__fail(err, OBS_NO_MEMORY, "reading the camera file");
        goto fail;
    }
    *len = fread(*buf, 1, MAX_JSON_BYTES + 1, fp);
    if (ferror(fp))
        st = obs__fail(err, OBS_IO, "read error");
    else if (*len > MAX_JSON_BYTES)
        st = obs__fail(err, OBS_TOO_LARGE, "larger than %d bytes; not a camera file", MAX_JSON_BYTES);
    else
        (*buf)[*len] = '\0';
fail:
    fclose(fp);
    if (st != OBS_OK) {
        free(*buf);
        *buf = NULL;
    }
    return st;
}

/* An optional finite number; *present says whether it was there. */
static obs_status get_number(const cJSON *root, const char *field, double *out, int *present,
                             char err[OBS_ERR_LEN])
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, field);
    *present = v != NULL;
    if (!v)
        return OBS_OK;
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
        return obs__fail(err, OBS_BAD_FILE, "%s: expected a number", field);
    *out = v->valuedouble;
    return OBS_OK;
}

/* A number the camera's floats hold: finite as a float (a double past
 * FLT_MAX would become an infinity). */
static int float_number(const cJSON *v)
{
    return cJSON_IsNumber(v) && fabs(v->valuedouble) <= FLT_MAX;
}

/* An optional 4x4 matrix: four rows of four numbers (or 16 numbers),
 * row-major. */
static obs_status get_mat4(const cJSON *root, const char *field, float m[16], int *present,
                           char err[OBS_ERR_LEN])
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, field);
    int n = 0, flat;
    *present = v != NULL;
    if (!v)
        return OBS_OK;
    if (!cJSON_IsArray(v))
        goto bad;
    flat = cJSON_GetArraySize(v) == 16;
    if (!flat && cJSON_GetArraySize(v) != 4)
        goto bad;
    const cJSON *row, *x;
    cJSON_ArrayForEach(row, v) {
        if (flat) {
            if (!float_number(row))
                goto bad;
            m[n++] = (float)row->valuedouble;
            continue;
        }
        if (!cJSON_IsArray(row) || cJSON_GetArraySize(row) != 4)
            goto bad;
        cJSON_ArrayForEach(x, row) {
            if (!float_number(x))
                goto bad;
            m[n++] = (float)x->valuedouble;
        }
    }
    return OBS_OK;
bad:
    return obs__fail(err, OBS_BAD_FILE, "%s: expected 4 rows of 4 numbers", field);
}

static obs_status parse_camera(const char *text, size_t len, obs_camera *cam, int *width_out,
                               int *height_out, char err[OBS_ERR_LEN])
{
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, len, &end, 0);
    double width = 0, height = 0, fov = 0, near_z = DEFAULT_NEAR, far_z = DEFAULT_FAR;
    int has_w, has_h, has_fov, has_near, has_far, has_wtc, has_proj;
    float inv[16];
    obs_status st;

    if (!root) {
        st = obs__fail(err, OBS_BAD_FILE, "not valid JSON (at byte %ld)",
                       end && end >= text ? (long)(end - text) : 0L);
        goto fail;
    }
    if (!cJSON_IsObject(root)) {
        st = obs__fail(err, OBS_BAD_FILE, "not a JSON object");
        goto fail;
    }
    memset(cam, 0, sizeof *cam);
    if ((st = get_number(root, "width", &width, &has_w, err)) != OBS_OK ||
        (st = get_number(root, "height", &height, &has_h, err)) != OBS_OK ||
        (st = get_number(root, "fov_y_deg", &fov, &has_fov, err)) != OBS_OK ||
        (st = get_number(root, "near", &near_z, &has_near, err)) != OBS_OK ||
        (st = get_number(root, "far", &far_z, &has_far, err)) != OBS_OK ||
        (st = get_mat4(root, "world_to_camera", cam->world_to_camera, &has_wtc, err)) != OBS_OK ||
        (st = get_mat4(root, "projection", cam->projection, &has_proj, err)) != OBS_OK)
        goto fail;

    const char *bad = NULL;
    if (has_w && (width != floor(width) || width < 1 || width > 1e9))
        bad = "width: expected a positive integer";
    else if (has_h && (height != floor(height) || height < 1 || height > 1e9))
        bad = "height: expected a positive integer";
    else if (has_fov && !(fov > 0 && fov < 180))
        bad = "fov_y_deg: expected degrees between 0 and 180";
    else if (!((float)near_z > 0))
        bad = "near: expected a positive distance";
    else if (!((float)far_z > (float)near_z) || !(far_z <= FLT_MAX))
        bad = "far: expected a distance beyond near"; /* as floats: the projection's */
    else if (!has_wtc)
        bad = "world_to_camera: missing";
    else if (obs__mat4_invert(cam->world_to_camera, inv) != 0)
        bad = "world_to_camera: the matrix is singular";
    else if (!has_proj && !(has_fov && has_w && has_h))
        bad = "projection: missing (and no fov_y_deg with width and height to build one)";
    if (bad) {
        st = obs__fail(err, OBS_BAD_FILE, "%s", bad);
        goto fail;
    }
    if (has_w && has_h && (st = obs_check_size(NULL, (int64_t)width, (int64_t)height, err)) != OBS_OK)
        goto fail;
    if (!has_proj) {
        float wtc[16];
        memcpy(wtc, cam->world_to_camera, sizeof wtc);
        obs_camera_from_fov((float)fov, (float)(width / height), (float)near_z, (float)far_z, cam);
        memcpy(cam->world_to_camera, wtc, sizeof wtc);
    }
    cam->has_world_to_camera = 1;
    cam->has_projection = 1;
    cam->source = OBS_CAMERA_JSON;
    if (width_out)
        *width_out = has_w ? (int)width : 0;
    if (height_out)
        *height_out = has_h ? (int)height : 0;
    st = OBS_OK;
fail:
    cJSON_Delete(root);
    return st;
}

obs_status obs_camera_read_json(const char *path, obs_camera *cam, int *width, int *height,
                                char err[OBS_ERR_LEN])
{
    char sub[OBS_ERR_LEN] = "";
    char *text = NULL;
    size_t len = 0;
    obs_camera parsed;
    obs_status st;

    if (!path || !cam)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_camera_read_json: NULL argument");
    if ((st = slurp(path, &text, &len, sub)) == OBS_OK &&
        (st = parse_camera(text, len, &parsed, width, height, sub)) == OBS_OK)
        *cam = parsed; /* *cam is left alone on failure */
    free(text);
    if (st != OBS_OK)
        return obs__fail(err, st, "%s: %s", path, sub);
    return OBS_OK;
}
