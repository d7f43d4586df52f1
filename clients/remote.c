/* The remote client of `obscura ao --server URL` (see remote.h): a
 * minimal HTTP/1.1 POST (Connection: close) and the binary protocol,
 * both over plain sockets. */
#include "remote.h"

#include <errno.h>
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "binary.h"
#include "obscura/io.h"

enum { RC_OK = 0, RC_FAIL = 1, RC_USAGE = 2, RC_BADINPUT = 3, RC_UNAVAILABLE = 4 };

#define ATTEMPTS 5         /* tries when unreachable or busy */
#define MAX_WAIT_S 5       /* the longest Retry-After honoured */
#define IO_TIMEOUT_S 300   /* send / receive timeout per call */
#define MAX_ANSWER (4ull << 30)

typedef enum { PROTO_HTTP, PROTO_UNIX, PROTO_TCP } proto;

typedef struct server_addr {
    proto kind;
    char host[256], port[16], path[108];
} server_addr;

static const char *stream_name; /* --stream NAME: post to /v1/streams/NAME/frames */

/* The warnings of the last answer (X-Obscura-Warning over HTTP, a 200's
 * message lines over the binary protocol), until
 * cli_remote_take_warnings() hands them on. */
static struct {
    int n;
    char text[OBS_EXR_WARNINGS][sizeof ((obs_exr_info *)0)->warnings[0]];
} said;

static void said_add(const char *text, size_t len)
{
    if (said.n < OBS_EXR_WARNINGS && len > 0)
        snprintf(said.text[said.n++], sizeof said.text[0], "%.*s", (int)len, text);
}

int cli_remote_take_warnings(obs_exr_info *info)
{
    int added = 0;
    for (int i = 0; i < said.n && info->warning_count < OBS_EXR_WARNINGS; i++) {
        int known = 0;
        for (int k = 0; k < info->warning_count && !known; k++)
            known = !strcmp(info->warnings[k], said.text[i]);
        if (known)
            continue; /* the input's, which this process checked and said itself */
        snprintf(info->warnings[info->warning_count++], sizeof info->warnings[0], "%s", said.text[i]);
        added++;
    }
    said.n = 0;
    return added;
}

static int stream_name_ok(const char *s)
{
    size_t n = strlen(s);
    return n >= 1 && n <= 64 && strspn(s, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") == n;
}

int cli_remote_take_server(int argc, char **argv, const char **server)
{
    int n = 0;
    *server = NULL;
    stream_name = NULL;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--server") && i + 1 < argc) {
            *server = argv[++i];
        } else if (!strncmp(argv[i], "--server=", 9)) {
            *server = argv[i] + 9;
        } else if (!strcmp(argv[i], "--stream") && i + 1 < argc) {
            stream_name = argv[++i];
        } else if (!strncmp(argv[i], "--stream=", 9)) {
            stream_name = argv[i] + 9;
        } else {
            argv[n++] = argv[i];
        }
    }
    if (stream_name && (!*server || !stream_name_ok(stream_name))) {
        fprintf(stderr, "obscura: error: --stream '%s': %s\n(run 'obscura help' for usage)\n", stream_name,
                !*server ? "needs --server http://HOST:PORT (streams live in obscurad)"
                         : "a stream name is 1 to 64 characters of A-Z a-z 0-9 . _ -");
        exit(RC_USAGE);
    }
    return n;
}

static int parse_server(const char *url, server_addr *a)
{
    memset(a, 0, sizeof *a);
    const char *rest;
    if (!strncmp(url, "unix:", 5)) {
        a->kind = PROTO_UNIX;
        rest = url + 5;
        if (!strncmp(rest, "//", 2))
            rest += 2;
        if (!*rest || strlen(rest) >= sizeof a->path)
            return -1;
        snprintf(a->path, sizeof a->path, "%s", rest);
        return 0;
    }
    if (!strncmp(url, "http://", 7)) {
        a->kind = PROTO_HTTP;
        rest = url + 7;
    } else if (!strncmp(url, "tcp://", 6)) {
        a->kind = PROTO_TCP;
        rest = url + 6;
    } else {
        return -1;
    }
    const char *colon = strrchr(rest, ':');
    size_t hl = colon ? (size_t)(colon - rest) : 0;
    if (!colon || hl == 0 || hl >= sizeof a->host)
        return -1;
    memcpy(a->host, rest, hl);
    if (a->host[0] == '[') { /* an IPv6 address, [::1]: getaddrinfo takes it bare */
        if (hl < 3 || a->host[hl - 1] != ']')
            return -1;
        memmove(a->host, a->host + 1, hl - 2);
        a->host[hl - 2] = '\0';
    }
    const char *p = colon + 1;
    size_t pl = strcspn(p, "/");
    if (pl == 0 || pl >= sizeof a->port || strspn(p, "0123456789") != pl || (p[pl] && strcmp(p + pl, "/")))
        return -1;
    memcpy(a->port, p, pl);
    return 0;
}

static void set_timeouts(int fd)
{
    struct timeval tv = {IO_TIMEOUT_S, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
}

/* -1 when the server cannot be reached (retryable). */
static int connect_to(const server_addr *a, char *why, size_t why_len)
{
    if (a->kind == PROTO_UNIX) {
        struct sockaddr_un sa = {.sun_family = AF_UNIX};
        snprintf(sa.sun_path, sizeof sa.sun_path, "%s", a->path);
        int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        if (fd >= 0 && connect(fd, (struct sockaddr *)&sa, sizeof sa) == 0) {
            set_timeouts(fd);
            return fd;
        }
        snprintf(why, why_len, "unix:%s: %s", a->path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM}, *res = NULL;
    int gai = getaddrinfo(a->host, a->port, &hints, &res);
    if (gai != 0) {
        snprintf(why, why_len, "%s:%s: %s", a->host, a->port, gai_strerror(gai));
        return -1;
    }
    int fd = -1;
    for (struct addrinfo *ai = res; ai && fd < 0; ai = ai->ai_next) {
        fd = socket(ai->ai_family, ai->ai_socktype | SOCK_CLOEXEC, ai->ai_protocol);
        if (fd >= 0 && connect(fd, ai->ai_addr, ai->ai_addrlen) != 0) {
            snprintf(why, why_len, "%s:%s: %s", a->host, a->port, strerror(errno));
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(res);
    if (fd >= 0) {
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        set_timeouts(fd);
    }
    return fd;
}

/* All len bytes sent (sending) or received, through interruptions; -1
 * on an error or a closed connection. */
static int transfer_all(int fd, char *buf, size_t len, int sending)
{
    for (size_t done = 0; done < len;) {
        ssize_t n = sending ? send(fd, buf + done, len - done, MSG_NOSIGNAL)
                            : recv(fd, buf + done, len - done, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        done += (size_t)n;
    }
    return 0;
}

static int send_all(int fd, const void *buf, size_t len)
{
    return transfer_all(fd, (char *)(uintptr_t)buf, len, 1); /* send only reads it */
}

static int recv_all(int fd, void *buf, size_t len) { return transfer_all(fd, buf, len, 0); }

/* ---- the parameters to forward ------------------------------------------- */

typedef struct pairs {
    obs_bin_param p[OBS_BIN_MAX_PARAMS];
    int n;
} pairs;

static void add(pairs *ps, const char *name, const char *value)
{
    if (ps->n < OBS_BIN_MAX_PARAMS)
        ps->p[ps->n++] = (obs_bin_param){name, value};
}

static int has(const pairs *ps, const char *name)
{
    for (int i = 0; i < ps->n; i++)
        if (!strcmp(ps->p[i].name, name))
            return 1;
    return 0;
}

/* The table's parameters as given (parse_ao has checked them), and with
 * `map_too` the channel-map options (the request options' NAMES rows;
 * output, format and float this client asks for itself).  Names keep
 * their spelling ('-' or '_'), which both protocols accept; leading "--"
 * is dropped. */
static void collect(int argc, char **argv, int map_too, pairs *ps, char names[][OBS_BIN_MAX_NAME + 1])
{
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "--", 2) != 0)
            continue;
        const char *eq = strchr(a + 2, '=');
        size_t n = eq ? (size_t)(eq - a - 2) : strlen(a + 2);
        if (n == 0 || n > OBS_BIN_MAX_NAME)
            continue;
        char *name = names[ps->n];
        snprintf(name, OBS_BIN_MAX_NAME + 1, "%.*s", (int)n, a + 2);
        int is_map = 0;
        for (const obs_http_option *op = obs_http_options; op->name; op++)
            /* the channel map's rows only: layer= and append= are this
             * client's, which writes the answer itself */
            is_map |= op->kind == OBS_HTTP_OPT_NAMES && op->map >= offsetof(obs_http_request, map) &&
                      op->map < offsetof(obs_http_request, map) + sizeof(obs_channel_map) &&
                      !strcmp(name, op->name);
        int is_param = obs_param_find(name) != NULL;
        /* the switches that change how the daemon reads the frame
         * (strict, solve_camera) go as name=1, or name=VALUE from
         * --name=VALUE; float is the client's */
        const obs_http_option *sw = obs_http_option_find(name);
        if (map_too && sw && sw->kind == OBS_HTTP_OPT_BOOL && strcmp(sw->name, "float") != 0) {
            snprintf(name, OBS_BIN_MAX_NAME + 1, "%s", sw->name);
            add(ps, name, eq ? eq + 1 : "1");
            continue;
        }
        if (!is_param && !(map_too && is_map))
            continue; /* a client option (its value, if any, is no "--" word) */
        const char *value = eq ? eq + 1 : (i + 1 < argc ? argv[++i] : "");
        add(ps, name, value);
    }
}

/* --compression's value, which the deep answer's file is written with
 * (the daemon writes --output deep's file, which this client keeps as
 * it comes); NULL when not given (auto: the file's default, as obscura
 * ao writes it). */
static const char *deep_compression(int argc, char **argv)
{
    for (int i = 0; i < argc; i++) {
        if (!strncmp(argv[i], "--compression=", 14))
            return argv[i] + 14;
        if (!strcmp(argv[i], "--compression") && i + 1 < argc)
            return argv[i + 1];
    }
    return NULL;
}

static const char *outputs_name(unsigned outputs)
{
    switch (outputs) {
    case OBS_OUTPUT_AO: return "ao";
    case OBS_OUTPUT_COMPOSITE: return "composite";
    case OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE: return "both";
    case OBS_OUTPUT_MULTIBOUNCE: return "multibounce";
    case OBS_OUTPUT_BENT: return "bent";
    case OBS_OUTPUT_AO | OBS_OUTPUT_MULTIBOUNCE | OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_BENT: return "aovs";
    case OBS_OUTPUT_DEEP: return "deep";
    default: return NULL;
    }
}

/* Exit code for a server's answer other than 200. */
static int answer_rc(int status)
{
    if (status == 503)
        return RC_UNAVAILABLE;
    return status >= 400 && status < 500 ? RC_BADINPUT : RC_FAIL;
}

static int copy_image(const float *src, size_t stride_floats, int w, int h, int ch, obs_image *out)
{
    size_t row = (size_t)w * ch;
    out->data = malloc(row * h * sizeof(float));
    if (!out->data)
        return -1;
    out->width = w;
    out->height = h;
    out->channels = ch;
    for (int y = 0; y < h; y++)
        memcpy(out->data + row * y, src + stride_floats * y, row * sizeof(float));
    return 0;
}

/* What an answer fills: a flat frame's result, or deep input's; with
 * output deep, the answer's deep EXR as it came (`file`). */
typedef struct answer {
    obs_result *flat;
    obs_deep_result *deep;
    obs_bytes *file;
} answer;

/* Keeps a copy of the answer's EXR in res->file.  0, or -1 out of memory. */
static int answer_file(answer *res, const unsigned char *body, size_t len, char *msg, size_t msg_len)
{
    if (!(res->file->data = malloc(len ? len : 1))) {
        snprintf(msg, msg_len, "out of memory for the answer");
        return -1;
    }
    memcpy(res->file->data, body, len);
    res->file->size = len;
    return 0;
}

static void answer_free(answer *a)
{
    /* each takes NULL */
    obs_result_free(a->flat);
    obs_deep_result_free(a->deep);
    obs_bytes_free(a->file);
}

/* Where a raw image of the answer goes (NULL: not one asked for). */
static obs_image *answer_slot(answer *a, unsigned output)
{
    if (a->deep)
        return output == OBS_OUTPUT_AO ? &a->deep->ao_blend
               : output == OBS_BIN_OUTPUT_AO_FRONT ? &a->deep->ao_front
               : output == OBS_OUTPUT_COMPOSITE ? &a->deep->composite : NULL;
    return output == OBS_OUTPUT_AO ? &a->flat->ao
           : output == OBS_OUTPUT_COMPOSITE ? &a->flat->composite
           : output == OBS_OUTPUT_MULTIBOUNCE ? &a->flat->multibounce
           : output == OBS_OUTPUT_SAMPLE_COUNT ? &a->flat->sample_count
           : output == OBS_OUTPUT_BENT ? &a->flat->bent : NULL;
}

/* ---- binary protocol ------------------------------------------------------ */

/* One attempt.  Returns 0 and fills res on 200; otherwise the status
 * (503 and -1 for "unreachable" are retried by the caller). */
static int binary_once(const server_addr *a, const obs_bytes *frame, answer *res, int *retry_after,
                       char *msg, size_t msg_len)
{
    int fd = connect_to(a, msg, msg_len);
    if (fd < 0)
        return -1;
    unsigned char hdr[OBS_BIN_HEADER_LEN];
    unsigned char *payload = NULL;
    obs_bin_header h;
    obs_bin_response r = {0};
    char err[OBS_ERR_LEN];
    int rc = -1;
    if (send_all(fd, frame->data, frame->size) != 0 || recv_all(fd, hdr, sizeof hdr) != 0) {
        snprintf(msg, msg_len, "connection lost: %s", strerror(errno));
        goto done;
    }
    if (obs_bin_header_parse(hdr, &h, MAX_ANSWER, err) != OBS_OK || h.kind != OBS_BIN_RESPONSE) {
        snprintf(msg, msg_len, "not an obscurad answer: %s", err);
        rc = 500;
        goto done;
    }
    if (!(payload = malloc(h.length ? (size_t)h.length : 1)) || recv_all(fd, payload, (size_t)h.length) != 0) {
        snprintf(msg, msg_len, "answer cut short");
        goto done;
    }
    if (obs_bin_response_decode(payload, (size_t)h.length, NULL, &r, err) != OBS_OK) {
        snprintf(msg, msg_len, "bad answer: %s", err);
        rc = 500;
        goto done;
    }
    if (r.status != 200) {
        snprintf(msg, msg_len, "%.63s: %.500s", r.code, r.message);
        *retry_after = r.retry_after;
        rc = r.status;
        goto done;
    }
    for (int i = 0; i < r.warning_count; i++)
        said_add(r.warnings[i], strlen(r.warnings[i]));
    if (res->file) {
        rc = r.body == OBS_BIN_EXR && answer_file(res, r.blob, r.blob_len, msg, msg_len) == 0 ? 0 : 500;
        goto done;
    }
    for (int i = 0; i < r.image_count; i++) {
        /* take the images over: they are ours */
        obs_image *slot = answer_slot(res, r.images[i].output);
        if (slot && !slot->data)
            *slot = r.images[i].image, r.images[i].image = (obs_image){0};
    }
    rc = 0;
done:
    obs_bin_response_free(&r);
    free(payload);
    close(fd);
    return rc;
}

/* ---- HTTP ----------------------------------------------------------------- */

static void url_encode(const char *s, char *out, size_t len)
{
    static const char hex[] = "0123456789ABCDEF";
    size_t o = 0;
    for (; *s && o + 4 < len; s++) {
        unsigned char c = (unsigned char)*s;
        if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
            strchr("-_.~,", c)) {
            out[o++] = (char)c;
        } else {
            out[o++] = '%';
            out[o++] = hex[c >> 4];
            out[o++] = hex[c & 15];
        }
    }
    out[o] = '\0';
}

static unsigned char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    unsigned char *buf = NULL;
    long n;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (buf = malloc((size_t)n)) && fread(buf, 1, (size_t)n, f) == (size_t)n) {
        *len = (size_t)n;
    } else {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    return buf;
}

/* One channel (`ao`, read as the depth) and/or R,G,B,A of the answer's
 * float EXR into images. */
static int exr_images(const unsigned char *body, size_t len, const char *ao, obs_image *ao_out,
                      const char *const *color, int color_ch, obs_image *color_out, char *msg,
                      size_t msg_len)
{
    obs_channel_map map = {.preset = "generic", .depth = ao ? ao : color_out ? color[0] : "R"};
    if (color_out)
        for (int c = 0; c < color_ch; c++)
            map.color[c] = color[c];
    obs_gbuffer_file gf = {0};
    char err[OBS_ERR_LEN];
    if (obs_gbuffer_read_exr_mem(body, len, &map, NULL, &gf, err) != OBS_OK) {
        snprintf(msg, msg_len, "cannot read the answer's EXR: %s", err);
        return -1;
    }
    const obs_gbuffer *g = &gf.gb;
    int rc = 0;
    if (ao)
        rc |= copy_image(g->depth.data, g->depth.row_stride ? g->depth.row_stride / 4 : (size_t)g->width,
                         g->width, g->height, 1, ao_out);
    if (color_out && !(rc |= copy_image(g->color.data, g->color.row_stride ? g->color.row_stride / 4
                                                                             : (size_t)g->width * 4,
                                         g->width, g->height, 4, color_out)) &&
        color_ch < 4) {
        /* the colour plane has 4 channels: keep the first color_ch */
        size_t n = (size_t)g->width * g->height;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < color_ch; c++)
                color_out->data[i * color_ch + c] = color_out->data[i * 4 + c];
        color_out->channels = color_ch;
    }
    obs_gbuffer_free(&gf);
    if (rc)
        snprintf(msg, msg_len, "out of memory");
    return rc ? -1 : 0;
}

/* The three channels `names` of the answer's EXR as one RGB image; none
 * of them there: no image (0), one missing or another error: -1. */
static int exr_vector(const unsigned char *body, size_t len, const char *const names[3], obs_image *out,
                      char *msg, size_t msg_len)
{
    obs_image ch[3] = {{0}};
    char err[OBS_ERR_LEN];
    int rc = 0, got = 0;
    for (int k = 0; k < 3 && !rc; k++) {
        obs_status s = obs_exr_read_channel_mem(body, len, names[k], NULL, &ch[k], err);
        got += s == OBS_OK;
        rc = s != OBS_OK && s != OBS_MISSING_CHANNEL;
    }
    if (!rc && got == 3) {
        size_t n = (size_t)ch[0].width * ch[0].height;
        if (ch[1].width != ch[0].width || ch[2].width != ch[0].width || ch[1].height != ch[0].height ||
            ch[2].height != ch[0].height || !(out->data = malloc(3 * n * sizeof(float)))) {
            rc = 1;
        } else {
            out->width = ch[0].width;
            out->height = ch[0].height;
            out->channels = 3;
            for (size_t i = 0; i < n; i++)
                for (int k = 0; k < 3; k++)
                    out->data[3 * i + k] = ch[k].data[i];
        }
    } else if (!rc && got) {
        rc = 1;
    }
    if (rc)
        snprintf(msg, msg_len, "cannot read the answer's %s: %s", names[0], got ? "incomplete" : err);
    for (int k = 0; k < 3; k++)
        obs_image_free(&ch[k]);
    return rc ? -1 : 0;
}

/* The answer's EXR (float; AO.Y, deep input's AOFront.Y, R,G,B,A; with
 * aovs or multibounce, AOMultiBounce.R,G,B and Samples.Y) back into
 * images. */
static int exr_to_result(const unsigned char *body, size_t len, unsigned outputs, answer *res,
                         char *msg, size_t msg_len)
{
    static const char *const rgba[] = {"R", "G", "B", "A"};
    static const char *const mb[] = {"AOMultiBounce.R", "AOMultiBounce.G", "AOMultiBounce.B"};
    static const char *const bent[] = {"BentNormal.X", "BentNormal.Y", "BentNormal.Z"};
    int ao = (outputs & OBS_OUTPUT_AO) != 0, comp = (outputs & OBS_OUTPUT_COMPOSITE) != 0;
    if (!res->deep) {
        obs_result *r = res->flat;
        if ((ao || comp) && exr_images(body, len, ao ? "AO.Y" : NULL, &r->ao, rgba, 4,
                                       comp ? &r->composite : NULL, msg, msg_len))
            return -1;
        /* the multi-bounce AO is left out of an answer without a colour plane */
        int count = (outputs & OBS_OUTPUT_SAMPLE_COUNT) != 0;
        if ((outputs & OBS_OUTPUT_MULTIBOUNCE) &&
            exr_images(body, len, count ? "Samples.Y" : NULL, &r->sample_count, mb, 3, &r->multibounce,
                       msg, msg_len))
            return -1;
        /* the bent normal (every method has one): read when there */
        return (outputs & OBS_OUTPUT_BENT) ? exr_vector(body, len, bent, &r->bent, msg, msg_len) : 0;
    }
    obs_deep_result *d = res->deep;
    if (exr_images(body, len, ao ? "AO.Y" : NULL, &d->ao_blend, rgba, 4, comp ? &d->composite : NULL, msg,
                   msg_len))
        return -1;
    return ao ? exr_images(body, len, "AOFront.Y", &d->ao_front, NULL, 0, NULL, msg, msg_len) : 0;
}

/* POSTs the frame to /v1/ao, or with `stream` to /v1/streams/STREAM/frames. */
static int http_once(const server_addr *a, const char *stream, const char *query, const unsigned char *body,
                     size_t body_len, unsigned outputs, answer *res, int *retry_after, char *msg, size_t msg_len)
{
    int fd = connect_to(a, msg, msg_len);
    if (fd < 0)
        return -1;
    const char *token = getenv("OBSCURA_TOKEN");
    size_t hcap = strlen(query) + 1024;
    char *head = malloc(hcap);
    unsigned char *ans = NULL;
    size_t alen = 0, acap = 0;
    int rc = -1;
    if (!head)
        goto done;
    char path[96] = "/v1/ao";
    if (stream)
        snprintf(path, sizeof path, "/v1/streams/%s/frames", stream);
    const int v6 = strchr(a->host, ':') != NULL; /* Host: [::1]:PORT */
    snprintf(head, hcap, "POST %s?%s HTTP/1.1\r\nHost: %s%s%s:%s\r\nContent-Type: image/x-exr\r\n"
             "Content-Length: %zu\r\nConnection: close\r\n%s%s%s\r\n", path, query, v6 ? "[" : "",
             a->host, v6 ? "]" : "", a->port, body_len,
             token && *token ? "Authorization: Bearer " : "", token && *token ? token : "",
             token && *token ? "\r\n" : "");
    /* a 413 or 401 may come before the body is read; the answer counts */
    int sent = send_all(fd, head, strlen(head)) == 0 && send_all(fd, body, body_len) == 0;
    for (;;) {
        if (alen == acap) {
            acap = acap ? acap * 2 : 1 << 16;
            unsigned char *p = acap <= MAX_ANSWER ? realloc(ans, acap) : NULL;
            if (!p)
                goto done;
            ans = p;
        }
        ssize_t n = recv(fd, ans + alen, acap - alen, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        alen += (size_t)n;
    }
    const unsigned char *end = NULL;
    for (size_t i = 0; i + 4 <= alen; i++)
        if (!memcmp(ans + i, "\r\n\r\n", 4)) {
            end = ans + i;
            break;
        }
    int status = 0;
    if (!end || sscanf((const char *)ans, "HTTP/1.%*d %d", &status) != 1) {
        snprintf(msg, msg_len, "%s", sent ? "no HTTP answer" : "connection lost while sending");
        goto done;
    }
    const unsigned char *payload = end + 4;
    size_t plen = alen - (size_t)(payload - ans);
    if (status != 200) {
        /* {"error": {"code": "...", "message": "..."}}: show the message */
        char text[1024];
        snprintf(text, sizeof text, "%.*s", (int)(plen < 1000 ? plen : 1000), (const char *)payload);
        const char *m = strstr(text, "\"message\":\"");
        snprintf(msg, msg_len, "HTTP %d: %.600s", status, m ? m + 11 : text);
        size_t ml = strlen(msg);
        if (ml >= 2 && !strcmp(msg + ml - 2, "}}"))
            msg[ml - 3] = '\0';
        for (const unsigned char *h = ans; h < end; h++)
            if (!strncasecmp((const char *)h, "\nRetry-After:", 13))
                *retry_after = atoi((const char *)h + 13);
        rc = status;
        goto done;
    }
    for (const unsigned char *h = ans; h < end; h++)
        if (!strncasecmp((const char *)h, "\nX-Obscura-Warning:", 19)) {
            const char *v = (const char *)h + 19;
            v += strspn(v, " \t");
            said_add(v, strcspn(v, "\r\n"));
        }
    if (res->file)
        rc = answer_file(res, payload, plen, msg, msg_len) == 0 ? 0 : 500;
    else
        rc = exr_to_result(payload, plen, outputs, res, msg, msg_len) == 0 ? 0 : 500;
done:
    free(head);
    free(ans);
    close(fd);
    return rc;
}

/* The camera the CLI chose, as query parameters, when it came from a
 * camera JSON (HTTP carries no projection matrix; fov_y, near and far
 * rebuild it). */
static void camera_params(const obs_gbuffer *gb, pairs *ps, char *buf, size_t len)
{
    if (!gb)
        return; /* deep input: the camera is the EXR's, or the parameters' */
    const obs_camera *c = &gb->camera;
    if (c->source != OBS_CAMERA_JSON || has(ps, "fov_y") || has(ps, "fov-y"))
        return;
    const float *p = c->projection;
    double fov = 2.0 * atan(1.0 / p[5]) * 180.0 / M_PI;
    double near_z = p[11] / (p[10] - 1.0), far_z = p[11] / (p[10] + 1.0);
    char *w2c = buf + 96;
    snprintf(buf, 32, "%.9g", fov);
    snprintf(buf + 32, 32, "%.9g", near_z);
    snprintf(buf + 64, 32, "%.9g", far_z);
    add(ps, "fov_y", buf);
    add(ps, "near", buf + 32);
    add(ps, "far", buf + 64);
    if (c->has_world_to_camera && !has(ps, "world_to_camera") && !has(ps, "world-to-camera")) {
        size_t o = 0;
        for (int k = 0; k < 16 && o < len - 96; k++)
            o += (size_t)snprintf(w2c + o, len - 96 - o, "%s%.9g", k ? "," : "", c->world_to_camera[k]);
        add(ps, "world_to_camera", w2c);
    }
}

/* ---- the run -------------------------------------------------------------- */

/* A stream post's failure that POST /v1/ao of the same server may not
 * share (no stream route or streams off: 404, 405; a daemon that keeps no
 * deep frames: 415; no memory to keep it: 500; anything unforeseen); not
 * the frame's own errors (400, 401, 413, 422: /v1/ao would say the same)
 * nor busy or unreachable (503, -1: already retried). */
static int stream_refused(int status)
{
    return status > 0 && status != 400 && status != 401 && status != 413 && status != 422 && status != 503;
}

static void sleep_s(int s)
{
    struct timespec ts = {s, 0};
    nanosleep(&ts, NULL);
}

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

/* Servers this process found unreachable are passed over for a while
 * (a batch worker runs many frames), unless every server is. */
#define DOWN_FOR_S 30.0
static struct {
    char url[256];
    double until;
} down[CLI_REMOTE_MAX_SERVERS];

static double down_until(const char *url)
{
    for (int i = 0; i < CLI_REMOTE_MAX_SERVERS; i++)
        if (!strcmp(down[i].url, url))
            return down[i].until;
    return 0;
}

static void mark_down(const char *url, double until)
{
    int slot = 0;
    for (int i = 0; i < CLI_REMOTE_MAX_SERVERS; i++) {
        if (!strcmp(down[i].url, url) || !down[i].url[0]) {
            slot = i;
            break;
        }
        if (down[i].until < down[slot].until)
            slot = i;
    }
    snprintf(down[slot].url, sizeof down[slot].url, "%.255s", url);
    down[slot].until = until;
}

int cli_remote_split(const char *list, char urls[][256], int max)
{
    int n = 0;
    for (const char *p = list;; p++) {
        size_t len = strcspn(p, ",");
        if (len == 0 || len >= 256 || n == max)
            return -1;
        memcpy(urls[n], p, len);
        urls[n][len] = '\0';
        n++;
        p += len;
        if (!*p)
            return n;
    }
}

/* The frame (gb or deep) on the servers; the answer into `out`. */
static int run_remote(const char *server, int argc, char **argv, const char *in_path, const obs_gbuffer *gb,
                      const obs_deep_image *deep, unsigned outputs, int half, answer *out)
{
    static server_addr addrs[CLI_REMOTE_MAX_SERVERS];
    static char urls[CLI_REMOTE_MAX_SERVERS][256];
    static pairs ps, pb; /* the HTTP and the binary parameters */
    static char names[OBS_BIN_MAX_PARAMS][OBS_BIN_MAX_NAME + 1], names_b[OBS_BIN_MAX_PARAMS][OBS_BIN_MAX_NAME + 1];
    char msg[OBS_ERR_LEN + 128] = "", cam[1024];
    const char *oname = outputs_name(outputs);
    int nserv = cli_remote_split(server, urls, CLI_REMOTE_MAX_SERVERS), any_http = 0, any_bin = 0;
    if (out->flat)
        memset(out->flat, 0, sizeof *out->flat);
    if (out->deep)
        memset(out->deep, 0, sizeof *out->deep);
    if (out->file)
        *out->file = (obs_bytes){0};
    ps.n = pb.n = 0;
    for (int k = 0; k < nserv; k++) {
        if (parse_server(urls[k], &addrs[k]) != 0) {
            nserv = -1;
            break;
        }
        any_http |= addrs[k].kind == PROTO_HTTP;
        any_bin |= addrs[k].kind != PROTO_HTTP;
    }
    if (nserv < 1) {
        fprintf(stderr, "obscura: error: --server '%s' is not http://HOST:PORT, unix:/PATH or tcp://HOST:PORT "
                "(or a comma-separated list of up to %d of them)\n", server, CLI_REMOTE_MAX_SERVERS);
        return RC_USAGE;
    }
    if (stream_name && any_bin) {
        fprintf(stderr, "obscura: error: --stream needs http:// servers (streams are an HTTP feature)\n");
        return RC_USAGE;
    }
    if (!oname) {
        fprintf(stderr, "obscura: error: --server: the daemon answers ao, composite, both, multibounce, bent, aovs or deep, not this --output\n");
        return RC_USAGE;
    }

    obs_bytes frame = {0};
    unsigned char *body = NULL;
    size_t body_len = 0;
    char *query = NULL;
    const char *token = getenv("OBSCURA_TOKEN");
    char err[OBS_ERR_LEN];
    int rc = RC_FAIL;
    if (any_http) {
        collect(argc, argv, 1, &ps, names);
        add(&ps, "output", oname);
        add(&ps, "format", "exr");
        /* half when the caller writes half (obscura ao's default EXR):
         * half -> float -> half is exact, so the file is the same bytes
         * as the float answer would give, at a quarter of the answer's
         * size and encode; float for PNG, --float and a combination */
        add(&ps, "float", half ? "0" : "1");
        if (out->file && deep_compression(argc, argv))
            add(&ps, "compression", deep_compression(argc, argv));
        /* the baked channel: this client combines it (obscura.c), so the
         * daemon does not do it a second time */
        add(&ps, "baked", "none");
        camera_params(gb, &ps, cam, sizeof cam);
        if (!(body = read_file(in_path, &body_len))) {
            fprintf(stderr, "obscura: error: %s: cannot read it to send\n", in_path);
            return RC_BADINPUT;
        }
        size_t qcap = 1;
        for (int i = 0; i < ps.n; i++)
            qcap += strlen(ps.p[i].name) + 3 * strlen(ps.p[i].value) + 2;
        if (!(query = malloc(qcap)))
            goto fail;
        size_t o = 0;
        for (int i = 0; i < ps.n; i++) {
            char v[3 * OBS_BIN_MAX_VALUE + 1];
            url_encode(ps.p[i].value, v, sizeof v);
            o += (size_t)snprintf(query + o, qcap - o, "%s%s=%s", i ? "&" : "", ps.p[i].name, v);
        }
    }
    /* Object masks are read by the daemon from the EXR itself (its
     * selectors name the file's channels, per sample on deep input): with
     * a mask the binary request carries the file, with the parameters an
     * HTTP request sends, instead of the planes, which have no place for
     * them */
    int masks = 0;
    char cam_b[1024];
    if (any_bin) {
        collect(argc, argv, 0, &pb, names_b);
        static const char *const mask_rows[] = {"receivers", "occluders", "self_only", "self-only"};
        for (int k = 0; k < 4; k++)
            masks |= has(&pb, mask_rows[k]);
        if (masks) { /* again, with the channel map's rows, as for HTTP */
            pb.n = 0;
            collect(argc, argv, 1, &pb, names_b);
        }
        add(&pb, "output", oname);
        add(&pb, "format", out->file ? "exr" : "raw"); /* deep: the file as it is */
        if (out->file && deep_compression(argc, argv))
            add(&pb, "compression", deep_compression(argc, argv));
        if (token && *token)
            add(&pb, "token", token);
        if (masks) {
            add(&pb, "baked", "none"); /* as for HTTP: this client combines it */
            camera_params(gb, &pb, cam_b, sizeof cam_b);
            if (!body && !(body = read_file(in_path, &body_len))) {
                fprintf(stderr, "obscura: error: %s: cannot read it to send\n", in_path);
                free(query);
                return RC_BADINPUT;
            }
        }
        obs_bin_request_desc d = {.id = 1,
                                  .params = pb.p,
                                  .param_count = pb.n,
                                  .gb = masks ? NULL : gb,
                                  .exr = masks ? body : NULL,
                                  .exr_len = masks ? body_len : 0,
                                  .deep = masks ? NULL : deep};
        if (obs_bin_request_encode(&d, &frame, err) != OBS_OK) {
            fprintf(stderr, "obscura: error: cannot encode the request: %s\n", err);
            goto fail;
        }
    }

    /* Each round tries the servers in the order given (obscura batch
     * rotates the list frame by frame), passing over one found down
     * lately; a busy (503) or unreachable server hands the frame to the
     * next.  When every server failed, wait and go round again. */
    int attempts = ATTEMPTS, last = -1, k_last = 0;
    const char *env = getenv("OBSCURA_RETRIES");
    if (env && *env)
        attempts = 1 + (atoi(env) < 0 ? 0 : atoi(env) > 100 ? 100 : atoi(env));
    for (int round = 1; round <= attempts; round++) {
        int wait = 1, tried = 0;
        double now = mono_s();
        for (int pass = 0; pass < 2 && !tried; pass++) /* pass 1: every server, if all are down */
            for (int k = 0; k < nserv; k++) {
                if (pass == 0 && nserv > 1 && down_until(urls[k]) > now)
                    continue;
                tried++;
                answer_free(out);
                said.n = 0;
                last = addrs[k].kind == PROTO_HTTP
                           ? http_once(&addrs[k], stream_name, query, body, body_len, outputs, out, &wait, msg,
                                       sizeof msg)
                           : binary_once(&addrs[k], &frame, out, &wait, msg, sizeof msg);
                k_last = k;
                if (last != -1 && last != 503)
                    goto answered;
                if (last == -1)
                    mark_down(urls[k], mono_s() + DOWN_FOR_S);
                if (nserv > 1)
                    fprintf(stderr, "obscura: warning: %s: %s; trying the next server\n", urls[k],
                            last == -1 ? msg : "busy (503)");
            }
        if (round == attempts)
            break;
        wait = wait < 1 ? 1 : wait > MAX_WAIT_S ? MAX_WAIT_S : wait;
        fprintf(stderr, "obscura: warning: %s: %s; retrying in %d s (%d of %d)\n", server,
                last == -1 ? msg : "busy (503)", wait, round, attempts - 1);
        sleep_s(wait);
    }
answered:
    rc = last;
    if (stream_name && stream_refused(rc)) {
        /* the stream is only a preview: the frame runs once more, on
         * /v1/ao of the server that answered, so that its result is not lost */
        fprintf(stderr, "obscura: warning: --stream %s: the stream post failed (%s); the result comes from "
                "POST /v1/ao and is written, but the frame is not in the stream\n", stream_name, msg);
        answer_free(out);
        int wait = 0;
        rc = http_once(&addrs[k_last], NULL, query, body, body_len, outputs, out, &wait, msg, sizeof msg);
    }
    free(query);
    free(body);
    obs_bytes_free(&frame);
    if (rc == 0)
        return RC_OK;
    answer_free(out);
    if (rc == -1) {
        fprintf(stderr, "obscura: error: %s: unreachable: %s\n", nserv > 1 ? server : urls[k_last], msg);
        return RC_UNAVAILABLE;
    }
    fprintf(stderr, "obscura: error: %s: %s%s\n", urls[k_last], msg, rc == 503 ? " (still busy after retries)" : "");
    return answer_rc(rc);
fail:
    free(query);
    free(body);
    obs_bytes_free(&frame);
    return RC_FAIL;
}

int cli_remote_run(const char *server, int argc, char **argv, const char *in_path,
                   const obs_gbuffer *gb, unsigned outputs, int half, obs_result *out)
{
    answer a = {out, NULL, NULL};
    return run_remote(server, argc, argv, in_path, gb, NULL, outputs, half, &a);
}

int cli_remote_run_deep(const char *server, int argc, char **argv, const char *in_path,
                        const obs_deep_image *deep, unsigned outputs, int half, obs_deep_result *out)
{
    answer a = {NULL, out, NULL};
    return run_remote(server, argc, argv, in_path, NULL, deep, outputs, half, &a);
}

int cli_remote_run_deep_file(const char *server, int argc, char **argv, const char *in_path,
                             const obs_deep_image *deep, obs_bytes *file)
{
    answer a = {NULL, NULL, file};
    return run_remote(server, argc, argv, in_path, NULL, deep, OBS_OUTPUT_DEEP, 0, &a);
}
