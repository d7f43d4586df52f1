/* The obscura/... keys every output carries (obs_provenance, io.h), as
 * key/value strings for the EXR and PNG writers (core/io/provenance.c). */
#ifndef OBSCURA_IO_PROVENANCE_H
#define OBSCURA_IO_PROVENANCE_H

#include "obscura/io.h"

#define OBS__PROV_KEYS 13 /* 5 of obscura/ and 8 of obs_provenance.attrs */

typedef struct obs__prov {
    int count;
    const char *key[OBS__PROV_KEYS];
    const char *value[OBS__PROV_KEYS];
    char method[32];
    char params[8192]; /* the table's every parameter fits: 16 floats at most per value */
} obs__prov;

/* Fills *out from p (NULL: obscura/version alone); the values point into
 * *out or into p's strings. */
void obs__prov_build(const obs_provenance *p, obs__prov *out);

#endif
