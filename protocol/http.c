/* The HTTP API's request parsing, status mapping and JSON bodies. */
#include "http.h"
#include "obscura/table.h"

#include <cjson/cJSON.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { Q = OBS_HTTP_QUERY, CLI = OBS_HTTP_CLI, ANY = Q | CLI };

/* The debug outputs are the CLI's only: obscurad answers AO, the
 * composite, the multi-bounce AO, the AOVs and a deep frame's deep EXR
 * (clients/remote.c refuses
 * the others with --server). */
static const obs_http_choice output_choices[] = {
    {"ao", OBS_OUTPUT_AO, ANY},
    {"composite", OBS_OUTPUT_COMPOSITE, ANY},
    {"both", OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE, ANY},
    {"samples", OBS_OUTPUT_SAMPLE_COUNT, CLI},
    {"cull", OBS_OUTPUT_CULL_MASK, CLI},
    {"bleed", OBS_OUTPUT_BLEED, CLI},
    {"luminance", OBS_OUTPUT_LUMINANCE, CLI},
    {"multibounce", OBS_OUTPUT_MULTIBOUNCE, ANY},
    /* a compositor's set in one EXR (README's "AOVs" table) */
    {"bent", OBS_OUTPUT_BENT, ANY},
    {"aovs", OBS_OUTPUT_AO | OBS_OUTPUT_MULTIBOUNCE | OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_BENT, ANY},
    {"deep", OBS_OUTPUT_DEEP, ANY}, /* deep input: the two-part deep EXR alone */
    {NULL, 0, 0}};
static const obs_http_choice format_choices[] = {
    {"exr", OBS_HTTP_EXR, ANY}, {"png", OBS_HTTP_PNG, ANY}, {NULL, 0, 0}};
static const obs_http_choice png_bits_choices[] = {{"8", 8, ANY}, {"16", 16, ANY}, {NULL, 0, 0}};
/* auto (0): ZIP for a file `obscura ao` writes, the daemon's fast
 * default for an answer (daemon/frame_path.c); the rest by OpenEXR's names */
static const obs_http_choice compression_choices[] = {
    {"auto", OBS_EXR_ZIP_DEFAULT, ANY}, {"none", OBS_EXR_NONE, ANY}, {"rle", OBS_EXR_RLE, ANY},
    {"zips", OBS_EXR_ZIPS, ANY},        {"zip", OBS_EXR_ZIP, ANY},   {"piz", OBS_EXR_PIZ, ANY},
    {"dwaa", OBS_EXR_DWAA, ANY},        {NULL, 0, 0}};
static const obs_http_choice png_transfer_choices[] = {
    {"srgb", OBS_PNG_TRANSFER_SRGB, ANY}, {"linear", OBS_PNG_TRANSFER_LINEAR, ANY}, {NULL, 0, 0}};

#define FIELD(f) offsetof(obs_http_request, f)
#define SLOT(f) sizeof ((obs_http_request *)0)->f

const obs_http_option obs_http_options[] = {
    /* a comma list in the CLI only: one answer holds AO and composite at most */
    {.name = "output", .kind = OBS_HTTP_OPT_CHOICE, .field = FIELD(outputs), .def = "ao",
     .choices = output_choices, .list = CLI,
     .doc = "what to return: the AO, the composited colour, or both (EXR only)"},
    {.name = "format", .kind = OBS_HTTP_OPT_CHOICE, .field = FIELD(format), .def = "exr",
     .choices = format_choices, .doc = "image format of the response"},
    {.name = "float", .kind = OBS_HTTP_OPT_BOOL, .field = FIELD(float_exr), .def = "0",
     .doc = "EXR: 32-bit float channels instead of half"},
    {.name = "compression", .kind = OBS_HTTP_OPT_CHOICE, .field = FIELD(compression), .def = "auto",
     .choices = compression_choices,
     .doc = "EXR: the output's compression; auto: zip for a file obscura ao writes, rle for "
            "obscurad's answer (fast to write; dwaa, lossy, needs OpenEXR 3.2)"},
    {.name = "png_bits", .kind = OBS_HTTP_OPT_CHOICE, .field = FIELD(png_bits), .def = "8",
     .choices = png_bits_choices, .doc = "PNG bit depth"},
    {.name = "png_transfer", .kind = OBS_HTTP_OPT_CHOICE, .field = FIELD(png_transfer), .def = "srgb",
     .choices = png_transfer_choices,
     .doc = "the AO PNG's transfer: sRGB-encoded and tagged, or linear values tagged linear"},
    {.name = "preset", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(preset), .def = "auto",
     .names = obs_channel_presets, .min = 1, .max = 1, .slot = SLOT(preset), .map = FIELD(map.preset),
     .doc = "channel-name preset of the G-buffer"},
    {.name = "depth", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(depth), .def = "", .min = 1,
     .max = 1, .slot = SLOT(depth), .map = FIELD(map.depth),
     .what = "a channel name (1 to 63 characters)", .doc = "depth channel name (overrides the preset)"},
    {.name = "normal", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(normal), .def = "", .min = 3,
     .max = 3, .slot = SLOT(normal[0]), .map = FIELD(map.normal),
     .what = "three channel names X,Y,Z", .doc = "normal channel names X,Y,Z"},
    {.name = "color", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(color), .def = "", .min = 1,
     .max = 4, .slot = SLOT(color[0]), .map = FIELD(map.color),
     .what = "beauty, albedo or three or four channel names R,G,B[,A]",
     .doc = "the colour plane: beauty (default), albedo, or channel names R,G,B[,A]"},
    {.name = "part", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(part), .def = "", .min = 1,
     .max = 1, .slot = SLOT(part), .map = FIELD(map.part),
     .what = "a part name or index (1 to 63 characters)",
     .doc = "the part of a multi-part EXR to read (name or index)"},
    {.name = "view", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(view), .def = "", .min = 1,
     .max = 1, .slot = SLOT(view), .map = FIELD(map.view),
     .what = "a view name (1 to 63 characters)",
     .doc = "the view of a multi-view EXR (default: its default view); its parts' channels are "
            "gathered"},
    {.name = "strict", .kind = OBS_HTTP_OPT_BOOL, .field = FIELD(strict), .def = "0",
     .doc = "sanity warnings on the input (depth looks normalized or inverted, normals not unit "
            "length or in the other space, camera metadata that disagrees) are errors"},
    {.name = "solve_camera", .kind = OBS_HTTP_OPT_BOOL, .field = FIELD(solve_camera), .def = "1",
     .doc = "with no camera in the file or the request: solve the pinhole camera from the "
            "file's world-space position pass (P, Position) (0: never)"},
    {.name = "layer", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(layer_name), .def = "", .min = 1, .max = 1,
     .slot = SLOT(layer_name), .map = FIELD(layer), .what = "a layer name (1 to 63 characters)",
     .doc = "EXR: the output's layer: NAME.Y for the AO, NAME.R,G,B,A for the composite (default AO.Y; R,G,B,A)"},
    {.name = "append", .kind = OBS_HTTP_OPT_BOOL, .field = FIELD(append), .def = "0",
     .doc = "EXR: the input file back, every part and channel unchanged, with the AO added as a layer"},
    {.name = "baked", .kind = OBS_HTTP_OPT_NAMES, .field = FIELD(baked_name), .def = "", .min = 1,
     .max = 1, .slot = SLOT(baked_name), .map = FIELD(baked),
     .what = "a channel name (1 to 63 characters), or none",
     .doc = "EXR: a baked AO channel of the input (obscura gbuffer of a level baked by obscura "
            "bake) combined with the chain's AO by baked_combine (AO.Y the combination, "
            "AOScreen.Y the chain's, AOBaked.Y the channel); default _AO when the input has it; "
            "none: not combined"},
    {.name = NULL}};

/* CHOICE and BOOL rows store through an int. */
_Static_assert(sizeof(obs_http_format) == sizeof(int) && sizeof(unsigned) == sizeof(int),
               "request option fields are int-sized");

/* The most names a NAMES row takes, and the longest slot. */
#define NAMES_MAX 4
#define SLOT_MAX 64

/* Copies "a,b,c" into n slots of `slot` bytes; returns how many names it
 * held, or -1 when one is empty or too long. */
static int split_names(const char *s, char *slots, size_t slot, int n)
{
    int k = 0;
    while (k < n) {
        const char *comma = strchr(s, ',');
        size_t len = comma ? (size_t)(comma - s) : strlen(s);
        if (len == 0 || len >= slot)
            return -1;
        memcpy(slots + k * slot, s, len);
        slots[k * slot + len] = '\0';
        k++;
        if (!comma)
            return k;
        s = comma + 1;
    }
    return -1; /* more names than slots */
}

/* "a|b|c": the choices of a row taken from `from`, for messages and
 * /v1/params. */
static const char *choices_text(const obs_http_option *op, unsigned from, char *buf, size_t len)
{
    size_t o = 0;
    buf[0] = '\0';
    if (op->kind == OBS_HTTP_OPT_BOOL)
        snprintf(buf, len, "0|1");
    for (const obs_http_choice *c = op->choices; c && c->name; c++)
        if ((c->from & from) && o < len)
            o += (size_t)snprintf(buf + o, len - o, "%s%s", o ? "|" : "", c->name);
    for (const char *const *n = op->names; n && *n; n++)
        if (o < len)
            o += (size_t)snprintf(buf + o, len - o, "%s%s", o ? "|" : "", *n);
    return buf;
}

static const obs_http_choice *find_choice(const obs_http_option *op, const char *s, size_t len,
                                          unsigned from)
{
    for (const obs_http_choice *c = op->choices; c->name; c++)
        if ((c->from & from) && strlen(c->name) == len && !strncmp(c->name, s, len))
            return c;
    return NULL;
}

/* The CLI's list skips empty items ("ao,,cull"), as it always has. */
static obs_status set_choice(obs_http_request *r, const obs_http_option *op, const char *value,
                             unsigned from, char err[OBS_ERR_LEN])
{
    char all[256];
    int v = 0, n = 0;
    const char *s = value;
    do {
        size_t len = op->list & from ? strcspn(s, ",") : strlen(s);
        const obs_http_choice *c = find_choice(op, s, len, from);
        if (c) {
            v |= c->value;
            n++;
        } else if (len || !(op->list & from)) {
            return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                                  "parameter %s: '%.*s' is not one of %s", op->name, (int)len, s,
                                  choices_text(op, from, all, sizeof all));
        }
        s += len;
    } while (*s++ == ',');
    if (!n)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "parameter %s: '%s' names none of %s",
                              op->name, value, choices_text(op, from, all, sizeof all));
    memcpy((char *)r + op->field, &v, sizeof v);
    return OBS_OK;
}

static obs_status set_bool(obs_http_request *r, const obs_http_option *op, const char *value,
                           char err[OBS_ERR_LEN])
{
    int v;
    /* on/off too: the words of the parameter table's switches, so one
     * spelling serves both (the Python client sends it for True/False) */
    if (!strcmp(value, "1") || !strcmp(value, "true") || !strcmp(value, "on") || !*value)
        v = 1;
    else if (!strcmp(value, "0") || !strcmp(value, "false") || !strcmp(value, "off"))
        v = 0;
    else
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "parameter %s: '%s' is not one of %s",
                              op->name, value, "0|1|true|false|on|off");
    memcpy((char *)r + op->field, &v, sizeof v);
    return OBS_OK;
}

/* Parsed into a copy first, so a bad value leaves the request as it was. */
static obs_status set_names(obs_http_request *r, const obs_http_option *op, const char *value,
                            char err[OBS_ERR_LEN])
{
    char tmp[NAMES_MAX * SLOT_MAX] = "", all[256];
    int k, known = !op->names;
    if (op->max < 1 || op->max > NAMES_MAX || op->slot > SLOT_MAX)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "parameter %s: its row takes more names than %d of %d bytes",
                              op->name, NAMES_MAX, SLOT_MAX);
    for (const char *const *n = op->names; n && *n; n++)
        known |= !strcmp(value, *n);
    if (!known)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "parameter %s: '%s' is not one of %s",
                              op->name, value, choices_text(op, Q, all, sizeof all));
    if (op->max == 1) { /* one name, whole: a comma may be part of it */
        k = *value && strlen(value) < op->slot ? 1 : -1;
        if (k == 1)
            memcpy(tmp, value, strlen(value) + 1);
    } else {
        k = split_names(value, tmp, op->slot, op->max);
    }
    if (k < op->min)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "parameter %s: '%.100s' is not %s",
                              op->name, value, op->what);
    char *slots = (char *)r + op->field;
    const char **map = (const char **)(void *)((char *)r + op->map);
    memcpy(slots, tmp, (size_t)op->max * op->slot);
    for (int i = 0; i < op->max; i++)
        map[i] = i < k ? slots + (size_t)i * op->slot : NULL;
    return OBS_OK;
}

const obs_http_option *obs_http_option_find(const char *name)
{
    for (const obs_http_option *op = obs_http_options; name && op->name; op++)
        if (obs_table_name_eq(op->name, name, strlen(name)))
            return op;
    return NULL;
}

obs_status obs_http_option_set(obs_http_request *r, const obs_http_option *op, const char *value,
                               obs_http_from from, char err[OBS_ERR_LEN])
{
    if (!value)
        value = "";
    switch (op->kind) {
    case OBS_HTTP_OPT_CHOICE: return set_choice(r, op, value, from, err);
    case OBS_HTTP_OPT_BOOL: return set_bool(r, op, value, err);
    case OBS_HTTP_OPT_NAMES: return set_names(r, op, value, err);
    }
    return obs_status_fail(err, OBS_INVALID_ARGUMENT, "parameter %s has an unknown kind", op->name);
}

void obs_http_request_init(obs_http_request *r)
{
    memset(r, 0, sizeof *r);
    for (const obs_http_option *op = obs_http_options; op->name; op++)
        if (op->kind != OBS_HTTP_OPT_NAMES)
            (void)obs_http_option_set(r, op, op->def, OBS_HTTP_QUERY, NULL);
}

obs_status obs_http_request_set(obs_http_request *r, const char *name, const char *value,
                                char err[OBS_ERR_LEN])
{
    const obs_http_option *op;
    if (!name || !*name)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "empty parameter name");
    if ((op = obs_http_option_find(name)))
        return obs_http_option_set(r, op, value, OBS_HTTP_QUERY, err);
    if (obs_param_find(name))
        return obs_param_set(&r->params, name, value ? value : "", err);
    return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                          "unknown parameter '%.100s' (GET /v1/params lists them)", name);
}

obs_status obs_http_value_check(const char *name, size_t name_len, const char *value, size_t len,
                                char err[OBS_ERR_LEN])
{
    if (name && memchr(name, '\0', name_len))
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "parameter '%.100s': its name holds a NUL byte (%%00)", name);
    if (value && memchr(value, '\0', len))
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "parameter %.100s: its value holds a NUL byte (%%00)",
                              name ? name : "?");
    return OBS_OK;
}

obs_status obs_http_request_set_n(obs_http_request *r, const char *name, size_t name_len, const char *value,
                                  size_t len, char err[OBS_ERR_LEN])
{
    obs_status s = obs_http_value_check(name, name_len, value, len, err);
    return s != OBS_OK ? s : obs_http_request_set(r, name, value, err);
}

obs_status obs_http_request_check(const obs_http_request *r, char err[OBS_ERR_LEN])
{
    if (r->format == OBS_HTTP_PNG && (r->outputs & (r->outputs - 1))) /* more than one */
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "format=png holds one image: ask for one output (output=ao, "
                              "output=composite or output=multibounce), or use format=exr for "
                              "both or aovs");
    if ((r->outputs & OBS_OUTPUT_DEEP) &&
        (r->outputs != OBS_OUTPUT_DEEP || r->format != OBS_HTTP_EXR || r->append || r->layer))
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "output=deep answers one deep EXR (deep input): not with other "
                              "outputs, format=png, append or layer");
    if (r->append && r->format != OBS_HTTP_EXR)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "append=1 writes the input EXR back with the AO added: it needs "
                              "format=exr");
    if (r->compression == OBS_EXR_DWAA && obs_exr_compression_check(OBS_EXR_DWAA, err) != OBS_OK)
        return OBS_INVALID_ARGUMENT; /* this build cannot: the request's fault to fix (400) */
    if (r->layer) {
        obs_exr_names names;
        obs_status s = obs_exr_layers_rename(NULL, 0, r->layer, &names, err);
        if (s != OBS_OK)
            return s;
    }
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
    case OBS_TOO_COSTLY: http = 422; c = "too_costly"; break;
    case OBS_DEADLINE: http = 422; c = "deadline_exceeded"; break;
    case OBS_CANCELLED: http = 409; c = "cancelled"; break;
    case OBS_GL_UNAVAILABLE: http = 500; c = "gl_unavailable"; break;
    case OBS_GL_SHADER: http = 500; c = "gl_shader"; break;
    default: http = 500; c = "gl_error"; break;
    }
    if (code)
        *code = c;
    return http;
}

/* The length of the UTF-8 sequence at s (n bytes left), or 0 when it is
 * not one (overlong, a surrogate, past U+10FFFF, cut short). */
static size_t utf8_len(const unsigned char *s, size_t n)
{
    unsigned c = s[0];
    size_t k;
    unsigned min, cp;
    if (c < 0x80)
        return 1;
    if (c >= 0xc2 && c <= 0xdf)
        k = 2, min = 0x80, cp = c & 0x1f;
    else if (c >= 0xe0 && c <= 0xef)
        k = 3, min = 0x800, cp = c & 0x0f;
    else if (c >= 0xf0 && c <= 0xf4)
        k = 4, min = 0x10000, cp = c & 0x07;
    else
        return 0;
    if (n < k)
        return 0;
    for (size_t i = 1; i < k; i++) {
        if ((s[i] & 0xc0) != 0x80)
            return 0;
        cp = cp << 6 | (s[i] & 0x3f);
    }
    if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
        return 0;
    return k;
}

/* A copy of s in which every byte that is not UTF-8 is U+FFFD. */
static char *utf8_clean(const char *s)
{
    size_t n = strlen(s);
    char *out = malloc(n * 3 + 1), *o = out;
    if (!out)
        return NULL;
    for (size_t i = 0; i < n;) {
        size_t k = utf8_len((const unsigned char *)s + i, n - i);
        if (k) {
            memcpy(o, s + i, k);
            o += k;
            i += k;
        } else {
            memcpy(o, "\xef\xbf\xbd", 3);
            o += 3;
            i++;
        }
    }
    *o = '\0';
    return out;
}

char *obs_http_error_json(const char *code, const char *message)
{
    cJSON *root = cJSON_CreateObject(), *e = cJSON_CreateObject();
    char *out = NULL, *c = utf8_clean(code ? code : "error"), *m = utf8_clean(message ? message : "");
    if (!root || !e || !c || !m) {
        cJSON_Delete(root);
        cJSON_Delete(e);
        free(c);
        free(m);
        return NULL;
    }
    cJSON_AddItemToObject(root, "error", e);
    if (cJSON_AddStringToObject(e, "code", c) && cJSON_AddStringToObject(e, "message", m))
        out = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    free(c);
    free(m);
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
    static const char *const types[] = {"float", "int", "enum", "mat4", "string"};
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
            if (pi->type == OBS_PARAM_STRING) /* its length in bytes */
                cJSON_AddNumberToObject(o, "max", pi->max);
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
        char choices[256];
        choices_text(op, OBS_HTTP_QUERY, choices, sizeof choices);
        cJSON_AddStringToObject(o, "name", op->name);
        cJSON_AddStringToObject(o, "type", op->kind == OBS_HTTP_OPT_BOOL ? "bool" : *choices ? "enum" : "string");
        cJSON_AddStringToObject(o, "default", op->def);
        if (*choices)
            cJSON_AddItemToObject(o, "choices", choices_array(choices));
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
