/* Decorator objects (section 2.2 of "Baked ambient obscurance on the
 * vertices of game levels"): which nodes of a level are decorators and of
 * which class (core/level/decor.c).  The bake traces them differently:
 * shrubs as fog boxes and trees as semi-transparent triangles in a second
 * BVH (section 2.1), small decorators get one scalar each (2.2.1). */
#ifndef OBSCURA_BAKE_DECOR_H
#define OBSCURA_BAKE_DECOR_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/bake.h"

enum {
    OBS__DECOR_NONE,  /* ordinary opaque geometry */
    OBS__DECOR_SHRUB, /* traced as fog: its world box with a density */
    OBS__DECOR_TREE,  /* a semi-transparent occluder */
    OBS__DECOR_SMALL  /* one scalar per instance (section 2.2.1) */
};

typedef struct obs__bake_decor {
    size_t node_count;
    uint8_t *node_class; /* OBS__DECOR_* per scene node; one allocation with density */
    float *density;      /* per node, fog density for shrubs (1/m), 0 otherwise */
    size_t counts[4];    /* nodes per class */
} obs__bake_decor;

/* Classifies every node of s.  decorators_json is the text of a
 * --decorators file (layout in README's bake section) or NULL; p the
 * resolved bake parameters (decorator_source, shrub_density).  Fails with
 * OBS_INVALID_ARGUMENT and a message naming the place for bad JSON or an
 * unknown class; returns OBS_OK with err holding a warning (err[0] != 0)
 * when entries of the file match no node.  Free with
 * obs__bake_decor_free(). */
obs_status obs__bake_decor_classify(const obs_bake_scene *s, const obs_bake_params *p,
                                    const char *decorators_json, obs__bake_decor *out,
                                    char err[OBS_ERR_LEN]);
/* The same with the warning moved out of err into warning ("" when none):
 * both bakes' decorator step. */
obs_status obs__bake_decor_classify_warn(const obs_bake_scene *s, const obs_bake_params *p,
                                         const char *decorators_json, obs__bake_decor *out,
                                         char warning[OBS_ERR_LEN], char err[OBS_ERR_LEN]);
void obs__bake_decor_free(obs__bake_decor *d);

/* The class named by a word: none|opaque, shrub|bush|hedge, tree|tree_line,
 * small|grass; -1 when unknown. */
int obs__bake_decor_class_of(const char *name);
const char *obs__bake_decor_class_name(int c);

#endif
