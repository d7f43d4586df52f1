/* The receivers mask applied to a result (core/mask_apply.c), by both
 * drivers of the flat chain and of the deep chain.  Not installed. */
#ifndef OBSCURA_MASK_APPLY_H
#define OBSCURA_MASK_APPLY_H

#include "obscura/deep.h"
#include "obscura/obscura.h"

/* AO' = 1 - w (1 - AO) with w = gb->receivers (nothing without it), the
 * multi-bounce AO's channels alike (the bent normal is left as it is),
 * and the composite made again from it: (1 - w) colour + w composite, the
 * colour's own value where w is 0 (exact without colour bleeding; with
 * it the unselected part of a pixel gets no bleed). */
void obs__receivers_apply(const obs_gbuffer *gb, obs_result *r);
/* The same on a deep result's ao_front and ao_blend, before its
 * composite, with d->receivers. */
void obs__receivers_apply_deep(const obs_deep_image *d, obs_deep_result *r);

#endif
