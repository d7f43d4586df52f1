/* Which nodes of a level are decorators (section 2.2 of the paper) and of
 * which class: shrubs (fog boxes, section 2.1), trees (semi-transparent,
 * section 2.1), small decorators (one scalar each, section 2.2.1), or
 * ordinary opaque geometry.  A node's own class comes, first found, from
 *   1. the --decorators file: rules {"name" | "match", "class", "density"}
 *      under "decorators", and TORCS' trees.json list "trees" as it is
 *      (its "kind": tree, tree_line, hedge);
 *   2. the node's glTF extras: our key "decorator", else 0 A.D.'s
 *      "class" (tree, bush, ...) and "kind" (grass, reeds, water_plant are
 *      small); a known key with another word (rock, terrain) is opaque;
 *   3. words of the node's name (tree, bush, shrub, hedge, grass);
 * (2 and 3 only with decorator_source auto).  A node with none of them takes its
 * parent's class and density: a tree's crown props stay the tree's. */
#include <cjson/cJSON.h>
#include <ctype.h>
#include <fnmatch.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "level/decor.h"
#include "internal.h"

#define CLASS_WORDS "none|shrub|tree|small (or opaque, bush, fruit_bush, hedge, fruit_tree, " \
                    "tree_line, grass, reeds, water_plant)"

static const struct {
    const char *word;
    int cls;
} words[] = {
    {"none", OBS__DECOR_NONE},        {"opaque", OBS__DECOR_NONE},
    {"shrub", OBS__DECOR_SHRUB},      {"bush", OBS__DECOR_SHRUB},
    {"fruit_bush", OBS__DECOR_SHRUB}, {"hedge", OBS__DECOR_SHRUB},
    {"tree", OBS__DECOR_TREE},        {"fruit_tree", OBS__DECOR_TREE},
    {"tree_line", OBS__DECOR_TREE},   {"small", OBS__DECOR_SMALL},
    {"grass", OBS__DECOR_SMALL},      {"reeds", OBS__DECOR_SMALL},
    {"water_plant", OBS__DECOR_SMALL},
};

int obs__bake_decor_class_of(const char *name)
{
    for (size_t i = 0; name && i < sizeof words / sizeof words[0]; i++)
        if (!strcmp(words[i].word, name))
            return words[i].cls;
    return -1;
}

const char *obs__bake_decor_class_name(int c)
{
    static const char *const n[] = {"none", "shrub", "tree", "small"};
    return c >= 0 && c < 4 ? n[c] : "?";
}

obs_status obs__bake_decor_classify_warn(const obs_bake_scene *s, const obs_bake_params *p,
                                         const char *decorators_json, obs__bake_decor *out,
                                         char warning[OBS_ERR_LEN], char err[OBS_ERR_LEN])
{
    warning[0] = 0;
    obs_status rc = obs__bake_decor_classify(s, p, decorators_json, out, err);
    if (rc != OBS_OK)
        return rc;
    snprintf(warning, OBS_ERR_LEN, "%s", err);
    err[0] = 0;
    return OBS_OK;
}

void obs__bake_decor_free(obs__bake_decor *d)
{
    if (!d)
        return;
    free(d->node_class); /* the block of both arrays (obs__alloc_arrays) */
    memset(d, 0, sizeof *d);
}

/* The class the words of a node's name say: its runs of letters,
 * lowercased, the last one that names a class ("flora/trees/bush_1" is a
 * bush); -1 when none does.  Whole words only: "street" is no tree. */
static int class_of_name(const char *name)
{
    static const struct {
        const char *w;
        int cls;
    } nw[] = {{"tree", OBS__DECOR_TREE},   {"trees", OBS__DECOR_TREE},
              {"bush", OBS__DECOR_SHRUB},  {"bushes", OBS__DECOR_SHRUB},
              {"shrub", OBS__DECOR_SHRUB}, {"shrubs", OBS__DECOR_SHRUB},
              {"hedge", OBS__DECOR_SHRUB}, {"hedges", OBS__DECOR_SHRUB},
              {"grass", OBS__DECOR_SMALL}};
    int found = -1;
    char w[16];
    for (const char *c = name ? name : ""; *c;) {
        if (!isalpha((unsigned char)*c)) {
            c++;
            continue;
        }
        size_t n = 0;
        for (; isalpha((unsigned char)*c); c++)
            if (n < sizeof w - 1)
                w[n++] = (char)tolower((unsigned char)*c);
        w[n] = 0;
        for (size_t i = 0; i < sizeof nw / sizeof nw[0]; i++)
            if (!strcmp(nw[i].w, w))
                found = nw[i].cls;
    }
    return found;
}

/* The class a node's extras give, with *density when they give one; -1
 * when they say nothing of it. */
static int class_of_extras(const char *extras, float *density)
{
    if (!extras)
        return -1;
    cJSON *x = cJSON_Parse(extras);
    int cls = -1;
    if (!cJSON_IsObject(x))
        goto done;
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(x, "decorator");
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(x, "class");
    const cJSON *k = cJSON_GetObjectItemCaseSensitive(x, "kind");
    if (cJSON_IsString(d)) {
        cls = obs__bake_decor_class_of(d->valuestring);
    } else {
        int kc = cJSON_IsString(k) ? obs__bake_decor_class_of(k->valuestring) : -1;
        int cc = cJSON_IsString(c) ? obs__bake_decor_class_of(c->valuestring) : -1;
        /* 0 A.D.: grass and reeds are class "other", kind "grass" */
        cls = kc == OBS__DECOR_SMALL ? kc : cc >= 0 ? cc : kc;
        if (cls < 0 && (cJSON_IsString(c) || cJSON_IsString(k)))
            cls = OBS__DECOR_NONE; /* rock, building, terrain, unit: opaque */
    }
    const cJSON *dn = cJSON_GetObjectItemCaseSensitive(x, "density");
    if (cls == OBS__DECOR_SHRUB && cJSON_IsNumber(dn) && dn->valuedouble >= 0.0 &&
        isfinite(dn->valuedouble))
        *density = (float)dn->valuedouble;
done:
    cJSON_Delete(x);
    return cls;
}

/* One rule of the file. */
typedef struct rule {
    const char *name, *match; /* exactly one */
    int cls;
    float density; /* < 0: not given */
    size_t hits;
} rule;

static obs_status parse_rule(const cJSON *e, const char *list, int i, int tree_list, rule *r,
                             char err[OBS_ERR_LEN])
{
    memset(r, 0, sizeof *r);
    r->density = -1.0f;
    if (!cJSON_IsObject(e))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "decorators file: %s[%d] is not an object",
                         list, i);
    const cJSON *n = cJSON_GetObjectItemCaseSensitive(e, "name");
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(e, "match");
    if ((n && !cJSON_IsString(n)) || (m && !cJSON_IsString(m)) || (!n == !m))
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "decorators file: %s[%d] needs one of \"name\" (a node name) or "
                         "\"match\" (a pattern, * and ?) as a string",
                         list, i);
    r->name = n ? n->valuestring : NULL;
    r->match = m ? m->valuestring : NULL;
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(e, "class");
    /* trees.json names the class "kind"; "class" wins when both are there */
    if (!c && tree_list)
        c = cJSON_GetObjectItemCaseSensitive(e, "kind");
    if (!c && tree_list) {
        r->cls = OBS__DECOR_TREE;
    } else if (!cJSON_IsString(c)) {
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "decorators file: %s[%d] ('%s') has no \"class\" string (%s)", list, i,
                         r->name ? r->name : r->match, CLASS_WORDS);
    } else if ((r->cls = obs__bake_decor_class_of(c->valuestring)) < 0) {
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "decorators file: %s[%d] ('%s'): unknown class '%s' (%s)", list, i,
                         r->name ? r->name : r->match, c->valuestring, CLASS_WORDS);
    }
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(e, "density");
    if (d) {
        if (!cJSON_IsNumber(d) || !(d->valuedouble >= 0.0) || !isfinite(d->valuedouble) ||
            d->valuedouble > 1000.0)
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "decorators file: %s[%d] ('%s'): density must be a number in "
                             "[0, 1000] (1/m)",
                             list, i, r->name ? r->name : r->match);
        r->density = (float)d->valuedouble;
    }
    return OBS_OK;
}

/* The rules of the file's text: n of them in *out (caller frees), the
 * parsed document in *doc (the rules' strings point into it). */
static obs_status parse_file(const char *text, cJSON **doc, rule **out, size_t *n,
                             char err[OBS_ERR_LEN])
{
    *out = NULL;
    *n = 0;
    cJSON *j = cJSON_Parse(text);
    *doc = j;
    if (!j) {
        const char *at = cJSON_GetErrorPtr();
        size_t line = 1;
        for (const char *c = text; at && c < at && *c; c++)
            line += *c == '\n';
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "decorators file: not JSON (error near line %zu: '%.20s')", line,
                         at ? at : "");
    }
    if (!cJSON_IsObject(j))
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "decorators file: expected an object with a \"decorators\" and/or a "
                         "\"trees\" array");
    const char *lists[2] = {"trees", "decorators"}; /* later rules win */
    const cJSON *arr[2];
    size_t total = 0;
    for (int l = 0; l < 2; l++) {
        arr[l] = cJSON_GetObjectItemCaseSensitive(j, lists[l]);
        if (arr[l] && !cJSON_IsArray(arr[l]))
            return obs__fail(err, OBS_INVALID_ARGUMENT, "decorators file: \"%s\" is not an array",
                             lists[l]);
        total += (size_t)cJSON_GetArraySize(arr[l]);
    }
    if (!arr[0] && !arr[1])
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "decorators file: no \"decorators\" or \"trees\" array");
    rule *r = calloc(total ? total : 1, sizeof *r);
    if (!r)
        return obs__fail(err, OBS_NO_MEMORY, "decorators file: %zu rules", total);
    for (int l = 0; l < 2; l++) {
        int i = 0;
        const cJSON *e;
        cJSON_ArrayForEach(e, arr[l])
        {
            obs_status st = parse_rule(e, lists[l], i++, l == 0, &r[*n], err);
            if (st != OBS_OK) {
                free(r);
                *n = 0;
                return st;
            }
            (*n)++;
        }
    }
    *out = r;
    return OBS_OK;
}

obs_status obs_bake_decorators_check(const char *text, size_t *rules, char err[OBS_ERR_LEN])
{
    cJSON *doc = NULL;
    rule *r = NULL;
    size_t n = 0;
    obs_status st = parse_file(text, &doc, &r, &n, err);
    free(r);
    cJSON_Delete(doc);
    if (rules)
        *rules = st == OBS_OK ? n : 0;
    return st;
}

static int rule_matches(const rule *r, const char *name)
{
    if (!name)
        return 0;
    return r->name ? !strcmp(r->name, name) : fnmatch(r->match, name, 0) == 0;
}

obs_status obs__bake_decor_classify(const obs_bake_scene *s, const obs_bake_params *p,
                                    const char *decorators_json, obs__bake_decor *out,
                                    char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    err[0] = 0;
    obs_bake_params rp;
    obs_bake_params_resolve(p, &rp);
    size_t nn = s ? s->node_count : 0;
    void *a[2];
    if (!obs__alloc_arrays(2, (const size_t[]){nn, nn * sizeof *out->density}, a))
        return obs__fail(err, OBS_NO_MEMORY, "decorator classes of %zu nodes", nn);
    out->node_class = a[0];
    out->density = a[1];
    out->node_count = nn;
    if (rp.decorator_source == OBS_BAKE_DECOR_OFF) {
        out->counts[OBS__DECOR_NONE] = nn;
        return OBS_OK;
    }
    cJSON *doc = NULL;
    rule *rules = NULL;
    size_t nr = 0;
    obs_status st = OBS_OK;
    if (decorators_json && (st = parse_file(decorators_json, &doc, &rules, &nr, err)) != OBS_OK)
        goto done;
    for (size_t n = 0; n < nn; n++) {
        const obs_bake_node *nd = &s->nodes[n];
        int cls = -1;
        float dens = -1.0f;
        for (size_t k = nr; k-- > 0;) /* the last matching rule wins */
            if (rule_matches(&rules[k], nd->name)) {
                if (cls < 0) {
                    cls = rules[k].cls;
                    dens = rules[k].density;
                }
                rules[k].hits++;
            }
        if (cls < 0 && rp.decorator_source == OBS_BAKE_DECOR_AUTO)
            cls = class_of_extras(nd->extras, &dens);
        if (cls < 0 && rp.decorator_source == OBS_BAKE_DECOR_AUTO)
            cls = class_of_name(nd->name);
        if (cls < 0 && nd->parent >= 0 && (size_t)nd->parent < n) {
            /* nodes are parents first: the parent's class is final */
            cls = out->node_class[nd->parent];
            dens = out->density[nd->parent];
        }
        if (cls < 0)
            cls = OBS__DECOR_NONE;
        out->node_class[n] = (uint8_t)cls;
        out->density[n] = cls != OBS__DECOR_SHRUB ? 0.0f : dens >= 0.0f ? dens : rp.shrub_density;
        out->counts[cls]++;
    }
    size_t unmatched = 0, first = 0;
    for (size_t k = 0; k < nr; k++)
        if (!rules[k].hits && !unmatched++)
            first = k;
    if (unmatched)
        snprintf(err, OBS_ERR_LEN,
                 "decorators file: %zu of %zu entries match no node (the first: '%s')",
                 unmatched, nr, rules[first].name ? rules[first].name : rules[first].match);
done:
    free(rules);
    cJSON_Delete(doc);
    if (st != OBS_OK)
        obs__bake_decor_free(out);
    return st;
}
