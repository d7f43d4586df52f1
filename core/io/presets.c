/* Renderer presets: the channel names, depth convention and normal space
 * each production renderer writes, and how a file says which renderer
 * wrote it (its header keys or software attribute).  Each row cites where
 * its convention comes from; what a renderer does not document is said
 * in README.md ("Input conventions") rather than guessed here.  The
 * blender and generic presets are channel_map.c's own. */
#include <stdio.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

#define L(...) ((const char *const[]){__VA_ARGS__, NULL})
#define NONE ((const char *const[]){NULL})

/* Each row names the beauty (the composite's colour by default; "" is
 * bare R,G,B,A) and then the diffuse albedo (--color albedo), each a
 * list of layer prefixes tried in order. */

static const obs__preset presets[] = {
    /* Arnold (driver_exr): AOVs are channels named after the AOV: Z
     * (camera-space depth along the view axis), N (world-space shading
     * normal) as N.X/Y/Z or N.R/G/B, the beauty as R,G,B,A; the header
     * carries arnold/... keys (arnold/version) and worldToCamera/worldToNDC
     * in Arnold's own screen space (core/camera/exr.c).  Source: Arnold
     * user guide, "AOVs" (Z, N: world space); the real frames in
     * ../shared/data/renderers/arnold (Arnold 4.2.16) have Z, N.X/Y/Z,
     * P.X/Y/Z; exrflatten's EXROperation_FixArnold detects Arnold by
     * arnold/version. */
    {"arnold", L("Z", "depth.Z", "Z.Z"), L("N", "normal"), L(""), L("diffuse_albedo", "albedo"),
     OBS_DEPTH_PLANAR, OBS_NORMALS_WORLD, L("arnold/"), L("Arnold")},
    /* V-Ray: render elements are layers named after the element:
     * "normals" (VRayNormals: camera space, Chaos docs "Normals Render
     * Element": "It stores the camera space normal map"), "diffuse"
     * (VRayDiffuseFilter), Z (the raw Z-depth channel of a multichannel
     * EXR); VRayZDepth is normalized between the element's zdepth
     * min/max (white near), which the file does not record, so it is not
     * mapped (channel_map.c says so).  Header: vrayInfo/... keys,
     * cameraTransform (camera to world) and cameraFov (horizontal,
     * degrees). */
    {"vray", L("Z", "VRayZDepthRaw.Z", "zdepth.Z"), L("normals", "VRayNormals"),
     L(""), L("diffuse", "VRayDiffuseFilter"), OBS_DEPTH_PLANAR, OBS_NORMALS_CAMERA,
     L("vrayInfo/", "vray/"), L("V-Ray", "VRay")},
    /* RenderMan: display channels z (camera-space depth) and Nn (the
     * normalized shading normal, in camera space: RenderMan's AOVs are
     * in "current" space), beauty Ci; RenderMan's EXR driver writes
     * the software as "RenderMan ...".  Source: RenderMan docs, "Output
     * Channels" / "Display Channels" (z, Nn, Ci); "albedo" is the AOV its
     * denoiser requires ("Denoising in RenderMan"). */
    {"renderman", L("z", "z.Z", "Z"), L("Nn", "N"), L("Ci", ""), L("albedo"), OBS_DEPTH_PLANAR,
     OBS_NORMALS_CAMERA, L("renderman/", "prman/"), L("RenderMan", "PRMan")},
    /* Redshift: AOVs Z (camera depth), N (world-space normals), beauty
     * R,G,B,A, DiffuseFilter; header rs/... keys (rs/camera/transform,
     * rs/camera/aperture, rs/camera/nearPlane, rs/camera/farPlane, as
     * MrLixm/nuke-tools-lxm metadataToCamera reads them).  Redshift does
     * not document the space of rs/camera/transform: obscura reads only
     * the standard attributes and the focal length/aperture. */
    {"redshift", L("Z", "Z.Z", "depth.Z"), L("N", "Normals"), L(""), L("DiffuseFilter"),
     OBS_DEPTH_PLANAR, OBS_NORMALS_WORLD, L("rs/"), L("Redshift")},
    /* Karma (Houdini Solaris): AOVs as LPE/primvar names: depth (the
     * planar camera depth, Karma's "depth" render var), N (world space),
     * C (beauty), albedo (the denoisers' albedo AOV).  Source: SideFX
     * docs, "Karma render variables"; software attribute "Karma". */
    {"karma", L("depth", "depth.Z", "Z"), L("N"), L("C", ""), L("albedo"), OBS_DEPTH_PLANAR,
     OBS_NORMALS_WORLD, L("karma/"), L("Karma")},
    /* Mantra (Houdini): image planes Pz (camera-space depth along the
     * view axis) and N (camera space: Mantra exports VEX globals in
     * camera space), beauty C.  Source: SideFX docs, "Mantra extra image
     * planes" (Pz, N); software attribute "Houdini"/"Mantra". */
    {"mantra", L("Pz", "Pz.Z", "Pz.R"), L("N"), L("C", ""), NONE, OBS_DEPTH_PLANAR,
     OBS_NORMALS_CAMERA, L("houdini/", "mantra/"), L("Mantra", "Houdini")},
    /* Octane: render passes "Z" (info pass "Z depth", raw when the max Z
     * depth is 0: camera distance along the view axis), "Normal" (the
     * shading normal in world space), "Diffuse filter".  Octane's
     * normalized Z-depth (clamped at max depth) is not described by the
     * file; see README.  Software attribute "Octane". */
    {"octane", L("Z", "Z-depth", "Z depth", "Zdepth"), L("Normal", "Shading normal"),
     L(""), L("Diffuse filter", "Diffuse"), OBS_DEPTH_PLANAR, OBS_NORMALS_WORLD, L("octane/"),
     L("Octane", "OctaneRender")},
    /* Nuke (ScanlineRender, DepthGenerator, Write): depth.Z holds 1/Z
     * (Foundry's ScanlineRender2 reference: "render world space distance
     * with 1/Z"; DepthGenerator's "depth" output defaults to 1/distance),
     * normals N (world space), rgba.  Header: nuke/... keys (the Write
     * node's nuke/node_hash, nuke/full_layer_names). */
    {"nuke", L("depth.Z", "depth.z", "Z"), L("N", "normals"), L(""), NONE, OBS_DEPTH_INVERSE,
     OBS_NORMALS_WORLD, L("nuke/"), L("Nuke")},
};

#define COUNT (sizeof presets / sizeof presets[0])

const obs__preset *obs__preset_find(const char *name)
{
    for (size_t i = 0; name && i < COUNT; i++)
        if (strcmp(presets[i].name, name) == 0)
            return &presets[i];
    return NULL;
}

const obs__preset *obs__preset_at(int i)
{
    return i >= 0 && (size_t)i < COUNT ? &presets[i] : NULL;
}

static int has_prefix(const char *s, const char *pre)
{
    return strncmp(s, pre, strlen(pre)) == 0;
}

const char *obs__preset_detect(exr_const_context_t ctx, int part, char *why, size_t len)
{
    static const char *const software_keys[] = {"software", "Software", "creator",
                                                "renderer", "writer", NULL};
    int32_t n = 0;
    const obs__preset *found = NULL;
    why[0] = '\0';
    if (exr_get_attribute_count(ctx, part, &n) != EXR_ERR_SUCCESS)
        n = 0;
    /* Blender's multilayer files say so (BlenderMultiChannel). */
    const exr_attribute_t *b = NULL;
    if (exr_get_attribute_by_name(ctx, part, "BlenderMultiChannel", &b) == EXR_ERR_SUCCESS && b) {
        snprintf(why, len, "header key BlenderMultiChannel");
        return "blender";
    }
    /* A key prefix is the surest sign: the first attribute that has one. */
    for (int32_t i = 0; i < n && !found; i++) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_index(ctx, part, EXR_ATTR_LIST_FILE_ORDER, i, &a) !=
                EXR_ERR_SUCCESS || !a || !a->name)
            continue;
        for (size_t k = 0; k < COUNT && !found; k++)
            for (const char *const *p = presets[k].keys; *p && !found; p++)
                if (has_prefix(a->name, *p)) {
                    found = &presets[k];
                    snprintf(why, len, "header key %s", a->name);
                }
    }
    for (const char *const *key = software_keys; *key && !found; key++) {
        const char *v = obs__exr_attr_string(ctx, part, *key);
        for (size_t k = 0; v && k < COUNT && !found; k++)
            for (const char *const *p = presets[k].software; *p && !found; p++)
                if (strstr(v, *p)) {
                    found = &presets[k];
                    snprintf(why, len, "%s \"%.60s\"", *key, v);
                }
    }
    return found ? found->name : NULL;
}
