/* The HTTP API's request parsing, status mapping and JSON bodies. */
#include "http.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const obs_http_option obs_http_options[] = {
    {"output", "enum", "ao", "ao|composite|both", "what to return: the AO, the composited colour, or both (EXR only)"},
    {"format", "enum", "exr", "exr|png", "image format of the response"},
    {"float", "bool", "0", "0|1", "EXR: 32-bit float channels instead of half"},
    {"png_bits", "enum", "8", "8|16", "PNG bit depth"},
    {"preset", "enum", "auto", "auto|blender|generic", "channel-name preset of the G-buffer"},
    {"depth", "string", "", NULL, "depth channel name (overrides the preset)"},
    {"normal", "string", "", NULL, "normal channel names X,Y,Z"},
    {"color", "string", "", NULL, "colour channel names R,G,B[,A]"},
    {NULL, NULL, NULL, NULL, NULL}};

static obs_status bad(char err[OBS_ERR_LEN], const char *fmt, const char *a, const char *b)
{
    if (err)
        snprintf(err, OBS_ERR_LEN, fmt, a, b);
    return OBS_INVALID_ARGUMENT;
}

static int name_is(const char *name, const char *want)
{
    for (; *name && *want; name++, want++) {
        char c = *name == '-' ? '_' : *name;
        if (c != *want)
            return 0;
    }
    return *name == *want;
}

/* Copies "a,b,c" into n fixed slots; returns how many names it held, or
 * -1 when one is empty or too long. */
static int split_names(const char *s, char (*slots)[64], int n)
{
    int k = 0;
    while (k < n) {
        const char *comma = strchr(s, ',');
        size_t len = comma ? (size_t)(comma - s) : strlen(s);
        if (len == 0 || len >= 64)
            return -1;
        memcpy(slots[k], s, len);
        slots[k][len] = '\0';
        k++;
        if (!comma)
            return k;
        s = comma + 1;
    }
    return -1; /* more names than slots */
}

void obs_http_request_init(obs_http_request *r)
{
    memset(r, 0, sizeof *r);
    r->outputs = OBS_OUTPUT_AO;
    r->format = OBS_HTTP_EXR;
    r->png_bits = 8;
}

obs_status obs_http_request_set(obs_http_request *r, const char *name, const char *value,
                                char err[OBS_ERR_LEN])
{
    if (!name || !*name)
        return bad(err, "empty parameter name%s%s", "", "");
    if (!value)
        value = "";
    if (name_is(name, "output")) {
        if (!strcmp(value, "ao"))
            r->outputs = OBS_OUTPUT_AO;
        else if (!strcmp(value, "composite"))
            r->outputs = OBS_OUTPUT_COMPOSITE;
        else if (!strcmp(value, "both"))
            r->outputs = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE;
        else
            return bad(err, "parameter output: '%s' is not one of %s", value, "ao|composite|both");
    } else if (name_is(name, "format")) {
        if (!strcmp(value, "exr"))
            r->format = OBS_HTTP_EXR;
        else if (!strcmp(value, "png"))
            r->format = OBS_HTTP_PNG;
        else
            return bad(err, "parameter format: '%s' is not one of %s", value, "exr|png");
    } else if (name_is(name, "float")) {
        if (!strcmp(value, "1") || !strcmp(value, "true") || !*value)
            r->float_exr = 1;
        else if (!strcmp(value, "0") || !strcmp(value, "false"))
            r->float_exr = 0;
        else
            return bad(err, "parameter float: '%s' is not one of %s", value, "0|1|true|false");
    } else if (name_is(name, "png_bits")) {
        if (!strcmp(value, "8") || !strcmp(value, "16"))
            r->png_bits = atoi(value);
        else
            return bad(err, "parameter png_bits: '%s' is not one of %s", value, "8|16");
    } else if (name_is(name, "preset")) {
        int ok = 0;
        for (int i = 0; obs_channel_presets[i]; i++)
            ok |= !strcmp(value, obs_channel_presets[i]);
        if (!ok)
            return bad(err, "parameter preset: '%s' is not one of %s", value, "auto|blender|generic");
        snprintf(r->preset, sizeof r->preset, "%s", value);
        r->map.preset = r->preset;
    } else if (name_is(name, "depth")) {
        if (!*value || strlen(value) >= sizeof r->depth)
            return bad(err, "parameter depth: '%.100s' is not a channel name (1 to 63 characters)%s", value, "");
        snprintf(r->depth, sizeof r->depth, "%s", value);
        r->map.depth = r->depth;
    } else if (name_is(name, "normal")) {
        if (split_names(value, r->normal, 3) != 3)
            return bad(err, "parameter normal: '%.100s' is not three channel names X,Y,Z%s", value, "");
        for (int i = 0; i < 3; i++)
            r->map.normal[i] = r->normal[i];
    } else if (name_is(name, "color")) {
        int k = split_names(value, r->color, 4);
        if (k != 3 && k != 4)
            return bad(err, "parameter color: '%.100s' is not three or four channel names R,G,B[,A]%s", value, "");
        for (int i = 0; i < 4; i++)
            r->map.color[i] = i < k ? r->color[i] : NULL;
    } else if (obs_param_find(name)) {
        return obs_param_set(&r->params, name, value, err);
    } else {
        return bad(err, "unknown parameter '%.100s' (GET /v1/params lists them)%s", name, "");
    }
    return OBS_OK;
}

obs_status obs_http_request_check(const obs_http_request *r, char err[OBS_ERR_LEN])
{
    if (r->format == OBS_HTTP_PNG && r->outputs == (OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE))
        return bad(err, "format=png holds one image: ask for one output (output=ao or "
                        "output=composite), or use format=exr for both%s%s", "", "");
    return OBS_OK;
}

int obs_http_status_of(obs_status s, const char **code)
{
    int http;
    const char *c;
    switch (s) {
    case OBS_OK: http = 200; c = "ok"; break;
    case OBS_INVALID_ARGUMENT: http = 400; c = "bad_parameter"; break;
    case OBS_TOO_LARGE: http = 413; c = "too_large"; break;
    case OBS_UNSUPPORTED: http = 415; c = "unsupported"; break;
    case OBS_MISSING_CHANNEL: http = 422; c = "missing_channel"; break;
    case OBS_NO_CAMERA: http = 422; c = "no_camera"; break;
    /* Reading from memory, an I/O error is the body's fault. */
    case OBS_BAD_FILE:
    case OBS_IO: http = 422; c = "bad_file"; break;
    case OBS_NO_MEMORY: http = 503; c = "no_memory"; break;
    case OBS_GL_UNAVAILABLE: http = 500; c = "gl_unavailable"; break;
    case OBS_GL_SHADER: http = 500; c = "gl_shader"; break;
    default: http = 500; c = "gl_error"; break;
    }
    if (code)
        *code = c;
    return http;
}

char *obs_http_error_json(const char *code, const char *message)
{
    cJSON *root = cJSON_CreateObject(), *e = cJSON_CreateObject();
    char *out = NULL;
    if (!root || !e) {
        cJSON_Delete(root);
        cJSON_Delete(e);
        return NULL;
    }
    cJSON_AddItemToObject(root, "error", e);
    if (cJSON_AddStringToObject(e, "code", code ? code : "error") &&
        cJSON_AddStringToObject(e, "message", message ? message : ""))
        out = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    return out;
}

static cJSON *choices_array(const char *choices)
{
    cJSON *a = cJSON_CreateArray();
    char buf[256];
    snprintf(buf, sizeof buf, "%s", choices);
    for (char *save = NULL, *t = strtok_r(buf, "|", &save); t && a; t = strtok_r(NULL, "|", &save))
        cJSON_AddItemToArray(a, cJSON_CreateString(t));
    return a;
}

char *obs_http_params_json(void)
{
    static const char *const types[] = {"float", "int", "enum", "mat4"};
    cJSON *root = cJSON_CreateObject(), *params, *opts;
    char *out = NULL;
    if (!root)
        return NULL;
    cJSON_AddStringToObject(root, "version", OBS_VERSION);
    params = cJSON_AddArrayToObject(root, "params");
    opts = cJSON_AddArrayToObject(root, "options");
    if (!params || !opts)
        goto done;
    for (int i = 0; i < obs_param_count(); i++) {
        const obs_param_info *pi = obs_param_at(i);
        cJSON *o = cJSON_CreateObject();
        if (!o)
            goto done;
        cJSON_AddItemToArray(params, o);
        cJSON_AddStringToObject(o, "name", pi->name);
        cJSON_AddStringToObject(o, "type", types[pi->type]);
        if (pi->type == OBS_PARAM_FLOAT || pi->type == OBS_PARAM_INT) {
            char *end;
            double d = strtod(pi->def, &end);
            if (*end == '\0')
                cJSON_AddNumberToObject(o, "default", d);
            else
                cJSON_AddStringToObject(o, "default", pi->def);
            cJSON_AddNumberToObject(o, "min", pi->min);
            cJSON_AddNumberToObject(o, "max", pi->max);
        } else {
            cJSON_AddStringToObject(o, "default", pi->def);
        }
        /* an int with choices takes only those numbers (samples: 2|4|8|16|32) */
        if ((pi->type == OBS_PARAM_ENUM || pi->type == OBS_PARAM_INT) && pi->choices)
            cJSON_AddItemToObject(o, "choices", choices_array(pi->choices));
        cJSON_AddStringToObject(o, "doc", pi->doc);
    }
    for (const obs_http_option *op = obs_http_options; op->name; op++) {
        cJSON *o = cJSON_CreateObject();
        if (!o)
            goto done;
        cJSON_AddItemToArray(opts, o);
        cJSON_AddStringToObject(o, "name", op->name);
        cJSON_AddStringToObject(o, "type", op->type);
        cJSON_AddStringToObject(o, "default", op->def);
        if (op->choices)
            cJSON_AddItemToObject(o, "choices", choices_array(op->choices));
        cJSON_AddStringToObject(o, "doc", op->doc);
    }
    out = cJSON_Print(root);
done:
    cJSON_Delete(root);
    return out;
}

int obs_http_bearer_ok(const char *authorization, const char *token)
{
    static const char prefix[] = "Bearer ";
    if (!authorization || !token || !*token || strncmp(authorization, prefix, sizeof prefix - 1) != 0)
        return 0;
    const char *got = authorization + sizeof prefix - 1;
    size_t n = strlen(got), m = strlen(token);
    unsigned char diff = n != m;
    for (size_t i = 0; i < m; i++)
        diff |= (unsigned char)(token[i] ^ got[i < n ? i : 0]);
    return diff == 0;
}
