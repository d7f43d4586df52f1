/* What the scene loaders share (scene.c): assimp's (scene.c) and the
 * baked .glb's (baked.c). */
#ifndef OBSCURA_GROUND_SCENE_INTERNAL_H
#define OBSCURA_GROUND_SCENE_INTERNAL_H

#include "obscura/scene.h"

/* obs_scene_check of the scene loaded from path, its message led by the
 * path. */
obs_status obs__scene_check_file(obs_scene *s, const char *path, char err[OBS_ERR_LEN]);

#endif
