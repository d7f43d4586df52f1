/* What core/io/crypto.c gives the mask builder (core/mask.c).  Not installed. */
#ifndef OBSCURA_IO_CRYPTO_H
#define OBSCURA_IO_CRYPTO_H

#include <stddef.h>

#include "obscura/mask.h"

/* 1 when a channel's name says it holds integer object or material IDs
 * (id, IndexOB, IndexMA, object_id, RenderID, ..., also LAYER.<one of
 * them> and <that>.X: Blender's ViewLayer.IndexOB.X). */
int obs__crypto_is_id_channel(const char *name);
/* The name of channel c (0 R .. 3 A) of rank set s (<name>NN) of L. */
void obs__crypto_channel(const obs_crypto_layer *L, int s, int c, char *buf, size_t len);

#endif
