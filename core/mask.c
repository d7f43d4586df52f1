/* Object masks: a selector (Cryptomatte names, integer IDs of a channel, a
 * coverage matte) read against an EXR into a weight plane in [0, 1], and
 * the G-buffer's receivers, occluders and object_id planes
 * (obscura/mask.h).  Coverage is Cryptomatte's: the matte of a set of IDs
 * is the sum of the coverage of the ranks holding one of them, never a
 * threshold. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "io/crypto.h"
#include "io/exr_internal.h"
#include "obscura/deep.h"
#include "obscura/mask.h"

#define MAX_PATTERNS 64
#define MAX_ID_RANGES 64

typedef enum { SEL_CRYPTO, SEL_ID, SEL_MATTE } sel_kind;

typedef struct {
    sel_kind kind;
    int negate;              /* "!SELECTOR": 1 - its weight */
    char layer[128];         /* SEL_CRYPTO: "@LAYER:" ("": every layer) */
    int npat;
    char pat[MAX_PATTERNS][256]; /* unescaped; wild marks which bytes are wildcards */
    char wild[MAX_PATTERNS][256];
    char channel[256];       /* SEL_ID, SEL_MATTE */
    int nrange;
    double lo[MAX_ID_RANGES], hi[MAX_ID_RANGES];
} selector;

/* ---- parsing ------------------------------------------------------------ */

static obs_status parse_crypto(const char *s, selector *sel, char err[OBS_ERR_LEN])
{
    if (s[0] == '@') {
        const char *colon = strchr(s, ':');
        if (!colon || colon == s + 1 || colon - s - 1 >= (long)sizeof sel->layer)
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "selector '%.200s': @LAYER: needs a layer name and a ':'", s);
        snprintf(sel->layer, sizeof sel->layer, "%.*s", (int)(colon - s - 1), s + 1);
        s = colon + 1;
    }
    int n = 0;
    size_t k = 0;
    for (const char *c = s;; c++) {
        if (*c == ',' || !*c) {
            if (k == 0)
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "selector '%.200s': an empty name (two commas, or one at an end)",
                                 s);
            sel->pat[n][k] = 0;
            n++;
            k = 0;
            if (!*c)
                break;
            if (n == MAX_PATTERNS)
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "selector: at most %d names", MAX_PATTERNS);
            continue;
        }
        if (k + 1 >= sizeof sel->pat[0])
            return obs__fail(err, OBS_INVALID_ARGUMENT, "selector: a name over %zu bytes",
                             sizeof sel->pat[0] - 1);
        int wild = (*c == '*' || *c == '?');
        if (*c == '\\') {
            if (!c[1])
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "selector '%.200s': a '\\' at its end escapes nothing", s);
            c++;
        }
        sel->wild[n][k] = (char)wild;
        sel->pat[n][k++] = *c;
    }
    sel->npat = n;
    return OBS_OK;
}

static obs_status parse_ids(const char *s, selector *sel, char err[OBS_ERR_LEN])
{
    const char *eq = strrchr(s, '=');
    if (!eq || eq == s || eq - s >= (long)sizeof sel->channel)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "selector 'id:%.200s': write id:CHANNEL=N[,N-M...]", s);
    snprintf(sel->channel, sizeof sel->channel, "%.*s", (int)(eq - s), s);
    const char *c = eq + 1;
    while (*c) {
        char *end;
        double lo = strtod(c, &end), hi = lo;
        if (end == c)
            goto bad;
        if (*end == '-') {
            c = end + 1;
            hi = strtod(c, &end);
            if (end == c || hi < lo)
                goto bad;
        }
        if (!isfinite(lo) || !isfinite(hi)) /* strtod's "nan" and "inf" */
            goto bad;
        if (sel->nrange == MAX_ID_RANGES)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "selector: at most %d IDs or ranges",
                             MAX_ID_RANGES);
        sel->lo[sel->nrange] = lo;
        sel->hi[sel->nrange++] = hi;
        if (*end == ',')
            end++;
        else if (*end)
            goto bad;
        c = end;
    }
    if (sel->nrange)
        return OBS_OK;
bad:
    return obs__fail(err, OBS_INVALID_ARGUMENT,
                     "selector 'id:%.200s': IDs are numbers N or ranges N-M (M >= N) separated "
                     "by ','",
                     s);
}

static obs_status parse_selector(const char *s, selector *sel, char err[OBS_ERR_LEN])
{
    memset(sel, 0, sizeof *sel);
    if (s && s[0] == '!') { /* everything but: Arnold's trace_set, inclusive off */
        sel->negate = 1;
        s++;
    }
    if (!s || !*s)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "selector: empty");
    if (!strncmp(s, "id:", 3)) {
        sel->kind = SEL_ID;
        return parse_ids(s + 3, sel, err);
    }
    if (!strncmp(s, "matte:", 6)) {
        sel->kind = SEL_MATTE;
        if (!s[6] || strlen(s + 6) >= sizeof sel->channel)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "selector '%.200s': matte:CHANNEL", s);
        snprintf(sel->channel, sizeof sel->channel, "%s", s + 6);
        return OBS_OK;
    }
    sel->kind = SEL_CRYPTO;
    return parse_crypto(!strncmp(s, "crypto:", 7) ? s + 7 : s, sel, err);
}

/* ---- matching ----------------------------------------------------------- */

/* Glob match of name against pattern p (wild[i]: p[i] is * or ?); '?'
 * takes one UTF-8 character.  Iterative, with one backtrack point (the
 * last '*'): time at most |p| |name|, whatever the pattern (a request's
 * selector is untrusted). */
static int glob(const char *p, const char *wild, const char *name)
{
    const char *star_p = NULL, *star_w = NULL, *star_n = NULL;
    while (*name) {
        if (*p && *wild && *p == '*') { /* remember it; first match nothing */
            star_p = ++p;
            star_w = ++wild;
            star_n = name;
        } else if (*p && *wild && *p == '?') {
            p++;
            wild++;
            name++;
            while ((*name & 0xC0) == 0x80)
                name++;
        } else if (*p && *p == *name) {
            p++;
            wild++;
            name++;
        } else if (star_p) { /* the last '*' takes one more character */
            p = star_p;
            wild = star_w;
            while ((*++star_n & 0xC0) == 0x80)
                ;
            name = star_n;
        } else {
            return 0;
        }
    }
    while (*p && *wild && *p == '*')
        p++, wild++;
    return !*p;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* ---- reading ------------------------------------------------------------ */

typedef struct {
    const char *path;
    const void *buf;
    size_t len;
    const obs_limits *lim;
    int deep; /* 1: a deep file, read at each pixel's front sample; 2: at
               * every sample (an image of the samples x 1) */
    int part;         /* the part to prefer (the G-buffer's); -1: none */
    const char *view; /* the view whose parts come first (the G-buffer's); NULL: none */
} source;

static obs_status read_ch(const source *src, const char *ch, obs_image *img,
                          char err[OBS_ERR_LEN])
{
    if (src->deep == 2) {
        const obs__exr_mem mem = {src->buf, src->len};
        obs_status st =
            obs__deep_read_samples(src->path, src->buf ? &mem : NULL, ch, src->lim, img, err);
        if (st == OBS_MISSING_CHANNEL) /* what the selector needs, said */
            st = obs__fail(err, st,
                           "the deep part has no per-sample channel '%.200s': the selector reads "
                           "it at every deep sample (README: Object masks, deep input)",
                           ch);
        return st;
    }
    if (src->deep) {
        const obs__exr_mem mem = {src->buf, src->len};
        return obs__deep_read_front(src->path, src->buf ? &mem : NULL, ch, src->lim, img, err);
    }
    const obs__exr_mem mem = {src->buf, src->len};
    const char *const one[1] = {ch};
    return obs__exr_read_channels(src->path, src->buf ? &mem : NULL, src->part, src->view, one, 1,
                                  src->lim, img, err);
}

static obs_status source_init(source *src, const char *path, const void *buf, size_t len,
                              const obs_limits *lim, char err[OBS_ERR_LEN])
{
    *src = (source){path, buf, len, lim, 0, -1, NULL};
    return buf ? obs_exr_is_deep_mem(buf, len, &src->deep, err)
               : obs_exr_is_deep(path, &src->deep, err);
}

static obs_status alloc_like(const obs_image *like, obs_image *out, float fill,
                             char err[OBS_ERR_LEN])
{
    size_t n = (size_t)like->width * (size_t)like->height;
    if (!(out->data = malloc(n * sizeof(float))))
        return obs__fail(err, OBS_NO_MEMORY, "mask plane of %dx%d", like->width, like->height);
    out->width = like->width;
    out->height = like->height;
    out->channels = 1;
    for (size_t i = 0; i < n; i++)
        out->data[i] = fill;
    return OBS_OK;
}

static uint32_t bits_of(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* Checks a plane read from the file against the size of the first. */
static obs_status same_size(const obs_image *a, const obs_image *b, const char *ch,
                            char err[OBS_ERR_LEN])
{
    if (a->width == b->width && a->height == b->height)
        return OBS_OK;
    return obs__fail(err, OBS_BAD_FILE, "channel %.150s is %dx%d, not %dx%d", ch, b->width,
                     b->height, a->width, a->height);
}

/* The 4 channels of every rank set of L (ID, coverage, ID, coverage), into
 * ch[4 * rank_sets]: in one pass over a flat file's chunks, else (deep)
 * one by one at the front samples. */
static obs_status read_ranks(const source *src, const obs_crypto_layer *L, obs_image *ch,
                             char err[OBS_ERR_LEN])
{
    char names[4 * OBS_CRYPTO_MAX_RANK_SETS][160];
    const char *np[4 * OBS_CRYPTO_MAX_RANK_SETS];
    const int n = 4 * L->rank_sets;
    for (int k = 0; k < n; k++) {
        obs__crypto_channel(L, k / 4, k % 4, names[k], sizeof names[k]);
        np[k] = names[k];
    }
    if (!src->deep) {
        const obs__exr_mem mem = {src->buf, src->len};
        return obs__exr_read_channels(src->path, src->buf ? &mem : NULL, src->part, src->view, np,
                                      n, src->lim, ch, err);
    }
    obs_status st = OBS_OK;
    for (int k = 0; k < n && st == OBS_OK; k++)
        st = read_ch(src, np[k], &ch[k], err);
    for (int k = 0; k < n && st != OBS_OK; k++)
        obs_image_free(&ch[k]);
    return st;
}

/* w = max(w, min(1, the sum of the coverage of L's ranks whose ID is in
 * ids)), w allocated (zero) at the first layer; the rank-0 ID into *dom
 * when dom is not NULL and has no data yet. */
static obs_status crypto_layer_weight(const source *src, const obs_crypto_layer *L,
                                      const uint32_t *ids, int nids, obs_image *w,
                                      obs_image *dom, char err[OBS_ERR_LEN])
{
    obs_image ch[4 * OBS_CRYPTO_MAX_RANK_SETS], sum = {0};
    obs_status st;
    if (L->rank_sets == 0)
        return obs__fail(err, OBS_MISSING_CHANNEL,
                         "Cryptomatte layer '%.100s': no rank channels %.100s00.R/G/B/A (or "
                         ".red/.green/.blue/.alpha)",
                         L->name, L->name);
    const int n = 4 * L->rank_sets;
    memset(ch, 0, sizeof ch);
    if ((st = read_ranks(src, L, ch, err)) != OBS_OK)
        return st;
    if ((st = alloc_like(&ch[0], &sum, 0.0f, err)) != OBS_OK)
        goto fail;
    for (int k = 1; k < n && st == OBS_OK; k++)
        st = same_size(&ch[0], &ch[k], L->name, err);
    if (st != OBS_OK)
        goto fail;
    const size_t np = (size_t)sum.width * (size_t)sum.height;
    if (dom && !dom->data) {
        if ((st = alloc_like(&ch[0], dom, 0.0f, err)) != OBS_OK)
            goto fail;
        memcpy(dom->data, ch[0].data, np * sizeof(float));
    }
    for (int r = 0; r < n / 2; r++) { /* rank r: its ID in ch[2r], coverage in ch[2r + 1] */
        const float *id = ch[2 * r].data, *cov = ch[2 * r + 1].data;
        for (size_t i = 0; i < np; i++) {
            uint32_t b = bits_of(id[i]);
            if (bsearch(&b, ids, (size_t)nids, sizeof b, cmp_u32))
                sum.data[i] += cov[i];
        }
    }
    if (!w->data && (st = alloc_like(&sum, w, 0.0f, err)) != OBS_OK)
        goto fail;
    if ((st = same_size(w, &sum, L->name, err)) != OBS_OK)
        goto fail;
    for (size_t i = 0; i < np; i++)
        w->data[i] = fmaxf(w->data[i], fminf(1.0f, fmaxf(0.0f, sum.data[i])));
fail:
    for (int k = 0; k < n; k++)
        obs_image_free(&ch[k]);
    obs_image_free(&sum);
    return st;
}

/* "a, b, c" of a layer's names, for a message. */
static void list_names(const obs_crypto_info *ci, char *buf, size_t len)
{
    size_t k = 0;
    buf[0] = 0;
    for (int l = 0; l < ci->layer_count; l++)
        for (int i = 0; i < ci->layers[l].entry_count && k + 8 < len; i++) {
            int m = snprintf(buf + k, len - k, "%s%s", k ? ", " : "", ci->layers[l].names[i]);
            if (m < 0 || (size_t)m >= len - k) {
                snprintf(buf + (len > 5 ? len - 5 : 0), 5, "...");
                return;
            }
            k += (size_t)m;
        }
}

static obs_status crypto_plane(const source *src, const selector *sel, obs_image *w,
                               obs_image *dom, char err[OBS_ERR_LEN])
{
    obs_crypto_info ci;
    uint32_t *ids = NULL;
    int matched_any = 0, layers_seen = 0;
    obs_status st = obs_crypto_describe(src->path, src->buf, src->len, &ci, err);
    if (st != OBS_OK)
        return st;
    char *pat_hit = calloc((size_t)sel->npat, 1);
    if (!pat_hit) {
        st = obs__fail(err, OBS_NO_MEMORY, "selector");
        goto fail;
    }
    for (int l = 0; l < ci.layer_count; l++) {
        const obs_crypto_layer *L = &ci.layers[l];
        if (sel->layer[0] && strcmp(sel->layer, L->name))
            continue;
        layers_seen++;
        if (L->manifest_error[0]) {
            st = obs__fail(err, OBS_BAD_FILE, "%s%s", L->manifest_error,
                           sel->layer[0] ? "" : " (@LAYER: in the selector picks another layer)");
            goto fail;
        }
        free(ids);
        if (!(ids = malloc(((size_t)L->entry_count + 1) * sizeof *ids))) {
            st = obs__fail(err, OBS_NO_MEMORY, "selector IDs");
            goto fail;
        }
        int nids = 0;
        for (int e = 0; e < L->entry_count; e++)
            for (int p = 0; p < sel->npat; p++)
                if (glob(sel->pat[p], sel->wild[p], L->names[e])) {
                    ids[nids++] = L->ids[e];
                    pat_hit[p] = 1;
                    break;
                }
        if (!nids)
            continue;
        qsort(ids, (size_t)nids, sizeof *ids, cmp_u32);
        matched_any = 1;
        if ((st = crypto_layer_weight(src, L, ids, nids, w, dom, err)) != OBS_OK)
            goto fail;
    }
    if (!layers_seen) {
        char list[512] = "";
        for (int l = 0; l < ci.layer_count; l++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", l ? ", " : "",
                     ci.layers[l].name);
        st = sel->layer[0]
                 ? obs__fail(err, OBS_INVALID_ARGUMENT,
                             "selector: no Cryptomatte layer '%.100s'; the file has: %.300s",
                             sel->layer, ci.layer_count ? list : "none")
                 : obs__fail(err, OBS_MISSING_CHANNEL,
                             "selector names Cryptomatte entries, but the file has no "
                             "Cryptomatte layer (id:CHANNEL=N or matte:CHANNEL for other masks)");
        goto fail;
    }
    for (int p = 0; p < sel->npat; p++)
        if (!pat_hit[p]) {
            char names[600];
            list_names(&ci, names, sizeof names);
            st = obs__fail(err, OBS_INVALID_ARGUMENT,
                           "selector: no Cryptomatte entry matches '%.100s'; the manifest has: "
                           "%.600s",
                           sel->pat[p], names);
            goto fail;
        }
    (void)matched_any;
fail:
    free(pat_hit);
    free(ids);
    obs_crypto_info_free(&ci);
    return st;
}

static obs_status id_plane(const source *src, const selector *sel, obs_image *w, obs_image *dom,
                           char err[OBS_ERR_LEN])
{
    obs_image ch = {0};
    obs_status st = read_ch(src, sel->channel, &ch, err);
    if (st != OBS_OK)
        return st;
    if ((st = alloc_like(&ch, w, 0.0f, err)) != OBS_OK) {
        obs_image_free(&ch);
        return st;
    }
    size_t n = (size_t)ch.width * (size_t)ch.height;
    /* integer IDs: a pixel holds one (an ID AOV is not filtered), so the
     * weight is 0 or 1 */
    for (size_t i = 0; i < n; i++)
        for (int r = 0; r < sel->nrange; r++)
            if (ch.data[i] >= sel->lo[r] && ch.data[i] <= sel->hi[r]) {
                w->data[i] = 1.0f;
                break;
            }
    if (dom)
        *dom = ch;
    else
        obs_image_free(&ch);
    return OBS_OK;
}

static obs_status matte_plane(const source *src, const selector *sel, obs_image *w,
                              char err[OBS_ERR_LEN])
{
    obs_status st = read_ch(src, sel->channel, w, err);
    if (st != OBS_OK)
        return st;
    for (size_t i = 0; i < (size_t)w->width * (size_t)w->height; i++)
        w->data[i] = w->data[i] > 0.0f ? fminf(1.0f, w->data[i]) : 0.0f; /* NaN: 0 */
    return OBS_OK;
}

static obs_status plane_of(const source *src, const char *text, obs_image *weight,
                           obs_image *dominant, char err[OBS_ERR_LEN])
{
    selector *sel = malloc(sizeof *sel);
    obs_status st;
    if (!sel)
        return obs__fail(err, OBS_NO_MEMORY, "selector");
    memset(weight, 0, sizeof *weight);
    if (dominant)
        memset(dominant, 0, sizeof *dominant);
    if ((st = parse_selector(text, sel, err)) == OBS_OK) {
        if (sel->kind == SEL_CRYPTO)
            st = crypto_plane(src, sel, weight, dominant, err);
        else if (sel->kind == SEL_ID)
            st = id_plane(src, sel, weight, dominant, err);
        else
            st = matte_plane(src, sel, weight, err);
    }
    if (st == OBS_OK && sel->negate)
        for (size_t i = 0; i < (size_t)weight->width * (size_t)weight->height; i++)
            weight->data[i] = 1.0f - weight->data[i];
    free(sel);
    if (st != OBS_OK) {
        obs_image_free(weight);
        if (dominant)
            obs_image_free(dominant);
    }
    return st;
}

obs_status obs_mask_plane(const char *path, const void *buf, size_t len, const char *selector_text,
                          const obs_limits *lim, obs_image *weight, obs_image *dominant,
                          char err[OBS_ERR_LEN])
{
    if ((!path && !buf) || !selector_text || !weight)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_mask_plane: NULL argument");
    source src;
    obs_status st = source_init(&src, path, buf, len, lim, err);
    return st == OBS_OK ? plane_of(&src, selector_text, weight, dominant, err) : st;
}

/* ---- the G-buffer's planes ---------------------------------------------- */

/* The selector self_only reads the objects from when neither receivers
 * nor occluders names a Cryptomatte layer or an ID channel: the first
 * Cryptomatte layer whose name has "object" (any case), else the first
 * layer, else the first ID channel. */
static obs_status default_source(const source *src, char *out, size_t len, char err[OBS_ERR_LEN])
{
    obs_crypto_info ci;
    obs_status st = obs_crypto_describe(src->path, src->buf, src->len, &ci, err);
    if (st != OBS_OK)
        return st;
    int pick = -1;
    for (int l = 0; l < ci.layer_count && pick < 0; l++) {
        char low[128];
        size_t k = 0;
        for (; ci.layers[l].name[k] && k + 1 < sizeof low; k++)
            low[k] = (char)(ci.layers[l].name[k] | 0x20);
        low[k] = 0;
        if (strstr(low, "object"))
            pick = l;
    }
    if (pick < 0 && ci.layer_count)
        pick = 0;
    if (pick >= 0)
        snprintf(out, len, "@%s:*", ci.layers[pick].name);
    else if (ci.id_count)
        snprintf(out, len, "id:%s=0-4294967295", ci.id_channels[0]);
    else
        st = obs__fail(err, OBS_MISSING_CHANNEL,
                       "self_only: the file has no Cryptomatte layer and no ID channel (id, "
                       "IndexOB, ...) to tell objects apart");
    obs_crypto_info_free(&ci);
    return st;
}

static int sel_has_objects(const char *s)
{
    s += s[0] == '!';
    return s[0] && strncmp(s, "matte:", 6) != 0;
}

obs_status obs_gbuffer_read_masks(obs_gbuffer_file *f, const char *path, const void *buf,
                                  size_t len, const obs_params *p, const obs_limits *lim,
                                  char err[OBS_ERR_LEN])
{
    if (!f || !p || (!path && !buf))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_gbuffer_read_masks: NULL argument");
    const int self = p->self_only == OBS_ON;
    if (!p->receivers[0] && !p->occluders[0] && !self)
        return OBS_OK;
    source src;
    obs_image recv = {0}, occl = {0}, dom = {0}, dom_w = {0};
    obs_status st = source_init(&src, path, buf, len, lim, err);
    if (st != OBS_OK)
        return st;
    src.part = f->info.part; /* the G-buffer's part and view first (--part, --view) */
    src.view = f->info.view;
    char self_sel[200];
    const int W = f->gb.width, H = f->gb.height;
    if (p->receivers[0] &&
        (st = plane_of(&src, p->receivers, &recv,
                       self && sel_has_objects(p->receivers) ? &dom : NULL, err)) != OBS_OK)
        goto fail;
    if (p->occluders[0] &&
        (st = plane_of(&src, p->occluders, &occl,
                       self && !dom.data && sel_has_objects(p->occluders) ? &dom : NULL, err)) !=
            OBS_OK)
        goto fail;
    if (self && !dom.data) {
        if ((st = default_source(&src, self_sel, sizeof self_sel, err)) != OBS_OK ||
            (st = plane_of(&src, self_sel, &dom_w, &dom, err)) != OBS_OK)
            goto fail;
    }
    const obs_image *pl[3] = {&recv, &occl, &dom};
    static const char *const what[3] = {"receivers", "occluders", "self_only"};
    size_t n = (size_t)W * (size_t)H, count = 0;
    for (int k = 0; k < 3; k++) {
        if (pl[k]->data && (pl[k]->width != W || pl[k]->height != H)) {
            st = obs__fail(err, OBS_BAD_FILE,
                           "%s: the mask's channels cover %dx%d pixels, the G-buffer %dx%d "
                           "(another part or data window)",
                           what[k], pl[k]->width, pl[k]->height, W, H);
            goto fail;
        }
        count += pl[k]->data ? n : 0;
    }
    free(f->mask_storage);
    if (!(f->mask_storage = malloc(count * sizeof(float)))) {
        st = obs__fail(err, OBS_NO_MEMORY, "mask planes of %dx%d", W, H);
        goto fail;
    }
    obs_plane *dst[3] = {&f->gb.receivers, &f->gb.occluders, &f->gb.object_id};
    float *at = f->mask_storage;
    for (int k = 0; k < 3; k++) {
        memset(dst[k], 0, sizeof *dst[k]);
        if (!pl[k]->data)
            continue;
        memcpy(at, pl[k]->data, n * sizeof(float));
        *dst[k] = (obs_plane){at, 1, 0};
        at += n;
        if (k < 2) {
            size_t any = 0;
            for (size_t i = 0; i < n; i++)
                any += pl[k]->data[i] > 0.0f;
            if (!any && f->info.warning_count < OBS_EXR_WARNINGS)
                snprintf(f->info.warnings[f->info.warning_count++], sizeof f->info.warnings[0],
                         "%s: the selector matches no pixel of this frame", what[k]);
        }
    }
fail:
    obs_image_free(&recv);
    obs_image_free(&occl);
    obs_image_free(&dom);
    obs_image_free(&dom_w);
    return st;
}

/* The occluders weight (when occl is not NULL) and self_only's object
 * (when id is not NULL) of every sample of a deep file: the selectors
 * read at every sample (src->deep 2), the objects from the same source as
 * the flat chain's (obs_gbuffer_read_masks): the receivers or occluders
 * selector's Cryptomatte layer or ID channel, else default_source. */
static obs_status deep_sample_masks(source *src, const obs_params *p, uint64_t samples,
                                    obs_image *occl, obs_image *id, char err[OBS_ERR_LEN])
{
    obs_image skip = {0};
    obs_status st = OBS_OK;
    char self_sel[200];
    src->deep = 2;
    if (id && p->receivers[0] && sel_has_objects(p->receivers))
        st = plane_of(src, p->receivers, &skip, id, err);
    obs_image_free(&skip);
    if (st == OBS_OK && (occl || (id && !id->data && p->occluders[0] &&
                                  sel_has_objects(p->occluders))))
        st = plane_of(src, p->occluders, occl ? occl : &skip,
                      id && !id->data && sel_has_objects(p->occluders) ? id : NULL, err);
    obs_image_free(&skip);
    if (st == OBS_OK && id && !id->data &&
        (st = default_source(src, self_sel, sizeof self_sel, err)) == OBS_OK)
        st = plane_of(src, self_sel, &skip, id, err);
    obs_image_free(&skip);
    const obs_image *pl[2] = {occl, id};
    for (int k = 0; k < 2 && st == OBS_OK; k++)
        if (pl[k] && pl[k]->data && (uint64_t)pl[k]->width * (uint64_t)pl[k]->height !=
                                        (samples ? samples : 1))
            st = obs__fail(err, OBS_BAD_FILE,
                           "%s: the mask covers %llu deep samples, the deep image has %llu",
                           k ? "self_only" : "occluders",
                           (unsigned long long)pl[k]->width * (unsigned long long)pl[k]->height,
                           (unsigned long long)samples);
    return st;
}

obs_status obs_deep_read_masks(obs_deep_image *d, const char *path, const void *buf, size_t len,
                               const obs_params *p, const obs_limits *lim, char err[OBS_ERR_LEN])
{
    if (!d || !p || (!path && !buf))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_deep_read_masks: NULL argument");
    const int self = p->self_only == OBS_ON;
    if (!p->receivers[0] && !p->occluders[0] && !self)
        return OBS_OK;
    source src;
    obs_image w = {0}, occl = {0}, id = {0};
    obs_status st = source_init(&src, path, buf, len, lim, err);
    /* receivers: at each pixel's front sample (what the flat AO shades) */
    if (st == OBS_OK && p->receivers[0])
        st = plane_of(&src, p->receivers, &w, NULL, err);
    if (st == OBS_OK && w.data && (w.width != d->width || w.height != d->height))
        st = obs__fail(err, OBS_BAD_FILE, "receivers: the mask covers %dx%d pixels, the deep "
                       "image %dx%d", w.width, w.height, d->width, d->height);
    /* occluders and self_only: at every sample, carried to the nodes the
     * list compression keeps (obs_deep_compress) */
    const uint64_t samples = d->offset ? d->offset[(size_t)d->width * (size_t)d->height] : 0;
    if (st == OBS_OK && (p->occluders[0] || self)) {
        st = deep_sample_masks(&src, p, samples, p->occluders[0] ? &occl : NULL,
                               self ? &id : NULL, err);
        if (st != OBS_OK) { /* which parameter asked, before the reason */
            char why[OBS_ERR_LEN];
            snprintf(why, sizeof why, "%s", err);
            st = obs__fail(err, st, "%s on deep input: %.400s",
                           p->occluders[0] && self ? "occluders, self_only"
                           : self                  ? "self_only"
                                                   : "occluders",
                           why);
        }
    }
    if (st != OBS_OK) {
        obs_image_free(&w);
        obs_image_free(&occl);
        obs_image_free(&id);
        return st;
    }
    if (w.data) {
        free(d->receivers);
        d->receivers = w.data; /* taken over */
    }
    free(d->occluders);
    free(d->object_id);
    d->occluders = samples ? occl.data : NULL; /* taken over */
    d->object_id = samples ? id.data : NULL;
    if (!samples) {
        obs_image_free(&occl);
        obs_image_free(&id);
    }
    return OBS_OK;
}
