/* assimp's importer through its C++ API (assimp_read.cpp), for both
 * loaders (ground/scene.c, level/load.c): read with validation only, then post-processing steps
 * applied in calls of their own, so that the scene can be checked in
 * between.  assimp 5.2's C aiApplyPostProcessing releases a scene that a
 * failing step has already deleted (a crash); Importer::ApplyPostProcessing
 * only returns NULL. */
#ifndef OBSCURA_GROUND_ASSIMP_READ_H
#define OBSCURA_GROUND_ASSIMP_READ_H

#include <stdint.h>
#include <stddef.h>

#include "obscura/status.h"

#ifdef __cplusplus
extern "C" {
#endif

struct aiScene;
typedef struct obs__assimp obs__assimp;

/* The file read with aiProcess_ValidateDataStructure and no other step
 * (keep_hierarchy: AI_CONFIG_PP_PTV_KEEP_HIERARCHY for a later
 * PreTransformVertices); NULL with assimp's message in msg when it cannot
 * be read, or out of memory. */
obs__assimp *obs__assimp_read(const char *path, int keep_hierarchy, char msg[OBS_ERR_LEN]);
const struct aiScene *obs__assimp_scene(const obs__assimp *a);
/* The steps (aiProcess_* flags) applied to the scene; NULL with assimp's
 * message in msg when one fails (the scene is then gone). */
const struct aiScene *obs__assimp_apply(obs__assimp *a, unsigned steps, char msg[OBS_ERR_LEN]);
void obs__assimp_free(obs__assimp *a);

/* What path must be before assimp reads it (assimp_check.c): a PLY
 * header ends with end_header; a .glb's chunks lie within the file; a
 * glTF's node graph is a forest (obs__glb_forest); an AC3D file's
 * structure, and its subdivided objects (assimp subdivides while it
 * reads) at most max_faces triangles.  OBS_OK, or the error
 * (OBS_BAD_FILE, OBS_TOO_LARGE, OBS_IO, OBS_NO_MEMORY). */
obs_status obs__assimp_precheck(const char *path, uint64_t max_faces, char err[OBS_ERR_LEN]);

/* Every face of the validated scene with at least one vertex (assimp
 * 5.2's Triangulate aborts on one without: ValidateDataStructure lets it
 * through). */
obs_status obs__assimp_faces(const char *path, const struct aiScene *sc, char err[OBS_ERR_LEN]);

/* The failure of assimp on path as a status and message: OBS_TOO_LARGE
 * when assimp ran out of memory (an allocation sized by a count in the
 * file), else OBS_BAD_FILE; `what` names what was expected ("a mesh", "a
 * level"), msg is assimp's message. */
obs_status obs__assimp_fail(const char *path, const char *what, const char *msg,
                            char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
