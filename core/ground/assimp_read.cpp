// assimp's importer through its C++ API (assimp_read.h).  No exception
// leaves this file.
#include "ground/assimp_read.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cstdio>
#include <exception>
#include <new>

struct obs__assimp {
    Assimp::Importer importer;
};

static void say(char *msg, const char *what)
{
    if (msg)
        std::snprintf(msg, OBS_ERR_LEN, "%s", what && *what ? what : "unknown error");
}

obs__assimp *obs__assimp_read(const char *path, int keep_hierarchy, char msg[OBS_ERR_LEN])
{
    obs__assimp *a = nullptr;
    try {
        a = new obs__assimp;
        if (keep_hierarchy)
            a->importer.SetPropertyBool(AI_CONFIG_PP_PTV_KEEP_HIERARCHY, true);
        if (a->importer.ReadFile(path, aiProcess_ValidateDataStructure))
            return a;
        say(msg, a->importer.GetErrorString());
    } catch (const std::exception &e) {
        say(msg, e.what());
    } catch (...) {
        say(msg, "unknown exception");
    }
    delete a;
    return nullptr;
}

const aiScene *obs__assimp_scene(const obs__assimp *a)
{
    return a ? a->importer.GetScene() : nullptr;
}

const aiScene *obs__assimp_apply(obs__assimp *a, unsigned steps, char msg[OBS_ERR_LEN])
{
    try {
        const aiScene *sc = a->importer.ApplyPostProcessing(steps);
        if (!sc)
            say(msg, a->importer.GetErrorString());
        return sc;
    } catch (const std::exception &e) {
        say(msg, e.what());
    } catch (...) {
        say(msg, "unknown exception");
    }
    return nullptr;
}

void obs__assimp_free(obs__assimp *a)
{
    try {
        delete a;
    } catch (...) {
    }
}
