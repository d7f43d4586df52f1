/* The one parameter table.
 *
 * Every tunable of the AO chain is declared once, here: name, type,
 * default, range, choices and a one-line doc.  The CLI flags and help, the
 * README's parameter list and (later) the HTTP and binary protocols are all
 * generated from this table.  A zero-initialised obs_params means "all
 * defaults"; obs_params_resolve() applies them in one place.
 */
#ifndef OBSCURA_PARAMS_H
#define OBSCURA_PARAMS_H

#include <stddef.h>

#include "obscura/status.h"
#include "obscura/table.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Enumerated parameter values.  Each enum is generated from one list,
 * X(VALUE, choice) in the order of the parameter's choices, and so is the
 * choices string of its row in the table below (OBS_CHOICES): the enum,
 * the names users give and the code cannot disagree.  Values are 1-based;
 * 0 always means "default". */
#define OBS__ENUM_VALUE(value, choice) value,
#define OBS__ENUM_CHOICE(value, choice) "|" #choice
/* "a|b|c" from a list (the leading '|' skipped). */
#define OBS_CHOICES(LIST) (LIST(OBS__ENUM_CHOICE) + 1)

#define OBS_DEPTH_MODE_LIST(X)                                                 \
    X(OBS_DEPTH_PLANAR, planar) /* distance along the camera axis (Depth.Z) */ \
    X(OBS_DEPTH_RADIAL, radial) /* distance from the camera centre */          \
    X(OBS_DEPTH_NDC, ndc)       /* OpenGL depth-buffer value in [0,1] */ \
    X(OBS_DEPTH_INVERSE, inverse) /* 1 / planar depth (Nuke's depth.Z) */    \
    X(OBS_DEPTH_NORMALIZED, normalized) /* (planar - near) / (far - near) */
typedef enum obs_depth_mode { OBS_DEPTH_DEFAULT, OBS_DEPTH_MODE_LIST(OBS__ENUM_VALUE) } obs_depth_mode;

#define OBS_SWITCH_LIST(X) X(OBS_ON, on) X(OBS_OFF, off)
typedef enum obs_switch { OBS_SWITCH_DEFAULT, OBS_SWITCH_LIST(OBS__ENUM_VALUE) } obs_switch;

/* Culling pre-pass, VAO++ section 4.2 (parameter `culling`). */
#define OBS_CULLING_LIST(X)                                                    \
    X(OBS_CULLING_OFF, off)                                                    \
    X(OBS_CULLING_GREEDY, greedy)   /* culling candidates get AO 1 */          \
    X(OBS_CULLING_CAREFUL, careful) /* culling candidates take the 4-sample set */
typedef enum obs_culling { OBS_CULLING_DEFAULT, OBS_CULLING_LIST(OBS__ENUM_VALUE) } obs_culling;

/* How the depth range check (VAO++ 4.4, eq 4) measures d (parameter
 * `range_distance`). */
#define OBS_RANGE_DISTANCE_LIST(X)                                             \
    X(OBS_RANGE_DISTANCE_NORMAL, normal) /* below the occluding surface, along its normal */ \
    X(OBS_RANGE_DISTANCE_VIEW, view)     /* behind the visible surface, along view Z */
typedef enum obs_range_distance {
    OBS_RANGE_DISTANCE_DEFAULT,
    OBS_RANGE_DISTANCE_LIST(OBS__ENUM_VALUE)
} obs_range_distance;

/* Luminance sensitivity, VAO++ section 4.3 (parameter `luminance`). */
#define OBS_LUMINANCE_LIST(X)                                                  \
    X(OBS_LUMINANCE_OFF, off)                                                  \
    X(OBS_LUMINANCE_LUM, lum)     /* Rec. 709 luminance of the colour */       \
    X(OBS_LUMINANCE_VALUE, value) /* HSV V: max(r, g, b) */
typedef enum obs_luminance { OBS_LUMINANCE_DEFAULT, OBS_LUMINANCE_LIST(OBS__ENUM_VALUE) } obs_luminance;

/* Colour bleeding, VAO++ section 4.7 (parameter `bleeding`). */
#define OBS_BLEEDING_LIST(X)                                                   \
    X(OBS_BLEEDING_OFF, off)                                                   \
    X(OBS_BLEEDING_FULL, full)       /* every sample */                        \
    X(OBS_BLEEDING_HALF, half)       /* every second sample */                 \
    X(OBS_BLEEDING_QUARTER, quarter) /* every fourth sample */
typedef enum obs_bleeding { OBS_BLEEDING_DEFAULT, OBS_BLEEDING_LIST(OBS__ENUM_VALUE) } obs_bleeding;

/* The AO method (parameter `method`); each has a row in the method table
 * (core/methods/methods.c). */
#define OBS_METHOD_LIST(X)                                                     \
    X(OBS_METHOD_VAOPP, vaopp)           /* VAO++: the whole chain */          \
    X(OBS_METHOD_VAO, vao)               /* plain VAO: no adaptive sampling, culling, range check */ \
    X(OBS_METHOD_HEMISPHERE, hemisphere) /* normal-oriented hemisphere SSAO */ \
    X(OBS_METHOD_ANGLE, angle)           /* angle-based paired-sample SSAO */  \
    X(OBS_METHOD_HBAO, hbao)             /* horizon-based AO */            \
    X(OBS_METHOD_GTAO, gtao)             /* ground-truth-based AO (XeGTAO) */
typedef enum obs_method {
    OBS_METHOD_DEFAULT,
    OBS_METHOD_LIST(OBS__ENUM_VALUE)
    OBS_METHOD_COUNT /* 1 + the last method */
} obs_method;

/* Where the AO is computed (parameter `ao_resolution`). */
#define OBS_RESOLUTION_LIST(X)                                                 \
    X(OBS_RESOLUTION_FULL, full) /* every pixel */                             \
    X(OBS_RESOLUTION_HALF, half) /* half of each axis, upsampled */
typedef enum obs_resolution {
    OBS_RESOLUTION_DEFAULT,
    OBS_RESOLUTION_LIST(OBS__ENUM_VALUE)
} obs_resolution;

/* Quality presets (parameter `quality`): each sets the parameters of its
 * rows in OBS_QUALITY_PRESETS that the request did not give. */
#define OBS_QUALITY_LIST(X)                                                    \
    X(OBS_QUALITY_PREVIEW, preview)                                            \
    X(OBS_QUALITY_STANDARD, default)                                           \
    X(OBS_QUALITY_HIGH, high)                                                  \
    X(OBS_QUALITY_REFERENCE, reference)
typedef enum obs_quality { OBS_QUALITY_UNSET, OBS_QUALITY_LIST(OBS__ENUM_VALUE) } obs_quality;

/* X(quality, parameter, value): what each preset sets (as text, through
 * obs_param_set); `default` sets nothing.  preview: the AO at half
 * resolution (a quarter of the pixels; upsampled by a joint bilateral
 * filter); high: the largest VAO++ sample set at every pixel that
 * adaptive sampling (4.1) leaves at its maximum; reference: the largest
 * set at every pixel, no adaptive sampling and no culling (4.2), the
 * chain's most samples and least approximation. */
#define OBS_QUALITY_PRESETS(X)                                                 \
    X(OBS_QUALITY_PREVIEW, ao_resolution, "half")                              \
    X(OBS_QUALITY_HIGH, samples, "32")                                         \
    X(OBS_QUALITY_REFERENCE, samples, "32")                                    \
    X(OBS_QUALITY_REFERENCE, adaptive, "off")                                  \
    X(OBS_QUALITY_REFERENCE, culling, "off")

/* Whether deep input's front and back faces bound intervals (parameter
 * `deep_intervals`); on and off keep the values of OBS_SWITCH_LIST. */
#define OBS_DEEP_INTERVALS_LIST(X)                                             \
    X(OBS_DEEP_INTERVALS_ON, on)                                               \
    X(OBS_DEEP_INTERVALS_OFF, off)                                             \
    X(OBS_DEEP_INTERVALS_AUTO, auto) /* on for method gtao, off for the VAO methods */
typedef enum obs_deep_intervals {
    OBS_DEEP_INTERVALS_DEFAULT,
    OBS_DEEP_INTERVALS_LIST(OBS__ENUM_VALUE)
} obs_deep_intervals;

/* X(parameter, value): method gtao on deep input with intervals in
 * effect (deep_intervals, facing flags, deep_mode multi) computes the
 * slice integral of Jimenez et al. as written, over the free arcs to the
 * AO distance D: the search radius D, a hard cut at it, no power, no
 * heuristics (XeGTAO's defaults compensate for one depth layer of unknown
 * thickness and 2 to 3 steps, which the intervals replace).  The steps:
 * where the free-arc sum has converged, the mean AO changing by under 2 %
 * of the occlusion to the next doubling, on a synthetic scene of closed
 * boxes (32 -> 64: 1.8 %); on the validation scenes it still moves by 2 to
 * 7 % from 32 to 64 (bench/QUALITY.md, "gtao's free arcs: the exact
 * integral by default").  Each parameter the request left unset takes its
 * value here; an explicit one keeps its own. */
#define OBS_DEEP_GTAO_EXACT(X)                                                 \
    X(gtao_radius_multiplier, "1")                                             \
    X(gtao_falloff, "1e-6")                                                    \
    X(gtao_power, "1")                                                         \
    X(gtao_heuristics, "off")                                                  \
    X(gtao_steps, "32")

/* What the VAO methods' AO measures (parameter `ao_definition`). */
#define OBS_AO_DEFINITION_LIST(X)                                              \
    X(OBS_AO_RAYS, rays)     /* a ray tracer's AO within radius: R = 2 radius, eq 1's V converted */ \
    X(OBS_AO_VOLUME, volume) /* the paper's volumetric obscurance: R = radius */
typedef enum obs_ao_definition {
    OBS_AO_DEFINITION_DEFAULT,
    OBS_AO_DEFINITION_LIST(OBS__ENUM_VALUE)
} obs_ao_definition;

/* The arc cosine of the angle-based method (parameter `angle_acos`). */
#define OBS_ACOS_LIST(X)                                                       \
    X(OBS_ACOS_QUADRATIC, quadratic) /* pi (1 - sign(x) x^2) / 2 */            \
    X(OBS_ACOS_LINEAR, linear)       /* pi (1 - x) / 2 */                      \
    X(OBS_ACOS_EXACT, exact)         /* acos(x) */
typedef enum obs_acos { OBS_ACOS_DEFAULT, OBS_ACOS_LIST(OBS__ENUM_VALUE) } obs_acos;

#define OBS_NORMAL_SPACE_LIST(X)                                               \
    X(OBS_NORMALS_WORLD, world)   /* world space: rotated by world_to_camera */ \
    X(OBS_NORMALS_CAMERA, camera) /* view space, camera looking down -Z */
typedef enum obs_normal_space {
    OBS_NORMALS_DEFAULT,
    OBS_NORMAL_SPACE_LIST(OBS__ENUM_VALUE)
} obs_normal_space;

/* Deep input (obscura/deep.h): parameters deep_mode and deep_hull. */
#define OBS_DEEP_MODE_LIST(X)                                                  \
    X(OBS_DEEP_MULTI, multi)   /* OITAO Algorithm 1 over every node */         \
    X(OBS_DEEP_SINGLE, single) /* the front node alone */
typedef enum obs_deep_mode { OBS_DEEP_MODE_DEFAULT, OBS_DEEP_MODE_LIST(OBS__ENUM_VALUE) } obs_deep_mode;

#define OBS_DEEP_HULL_LIST(X)                                                  \
    X(OBS_DEEP_SOLID, solid) /* OITAO eq 1: solid volumes */                   \
    X(OBS_DEEP_THIN, thin)   /* OITAO eqs 2-4: thin hulls */
typedef enum obs_deep_hull { OBS_DEEP_HULL_DEFAULT, OBS_DEEP_HULL_LIST(OBS__ENUM_VALUE) } obs_deep_hull;

/* How `obscura ao --baked CH` combines a baked AO channel of the G-buffer
 * with the chain's AO (parameter `baked_combine`; obs_result_combine_baked). */
#define OBS_BAKED_COMBINE_LIST(X)                                              \
    X(OBS_BAKED_PRODUCT, product) /* baked x screen-space */                   \
    X(OBS_BAKED_MIN, min)         /* the darker of the two */
typedef enum obs_baked_combine {
    OBS_BAKED_COMBINE_DEFAULT,
    OBS_BAKED_COMBINE_LIST(OBS__ENUM_VALUE)
} obs_baked_combine;

/* Every ENUM row of the table and its list, for the test that walks them
 * (tests/unit/core/test_params.c).  X(parameter, LIST) */
#define OBS_PARAM_ENUMS(X)                                                     \
    X(method, OBS_METHOD_LIST)                                                 \
    X(quality, OBS_QUALITY_LIST)                                               \
    X(ao_resolution, OBS_RESOLUTION_LIST)                                      \
    X(ao_definition, OBS_AO_DEFINITION_LIST)                                   \
    X(adaptive, OBS_SWITCH_LIST)                                               \
    X(culling, OBS_CULLING_LIST)                                               \
    X(depth_mode, OBS_DEPTH_MODE_LIST)                                         \
    X(normal_space, OBS_NORMAL_SPACE_LIST)                                     \
    X(range_check, OBS_SWITCH_LIST)                                            \
    X(range_distance, OBS_RANGE_DISTANCE_LIST)                                 \
    X(blur, OBS_SWITCH_LIST)                                                   \
    X(luminance, OBS_LUMINANCE_LIST)                                           \
    X(bleeding, OBS_BLEEDING_LIST)                                             \
    X(angle_acos, OBS_ACOS_LIST)                                               \
    X(gtao_heuristics, OBS_SWITCH_LIST)                                        \
    X(deep_mode, OBS_DEEP_MODE_LIST)                                           \
    X(deep_front_half, OBS_SWITCH_LIST)                                        \
    X(deep_hull, OBS_DEEP_HULL_LIST)                                           \
    X(deep_intervals, OBS_DEEP_INTERVALS_LIST)                                 \
    X(baked_combine, OBS_BAKED_COMBINE_LIST)                                   \
    X(multibounce, OBS_SWITCH_LIST)                                            \
    X(self_only, OBS_SWITCH_LIST)

/* X(name, type, default, min, max, choices, doc)
 * type: FLOAT, INT, ENUM (choices '|'-separated, stored 1-based), MAT4,
 * STRING (char[max + 1], at most max bytes; default "").
 * An INT with choices takes only the listed numbers (within min..max). 
 * For ENUM the default is the choice's name; for MAT4 it is unused. */
/* The longest object-mask selector (receivers, occluders), in bytes. */
#define OBS_SELECTOR_MAX 1023

#define OBS_PARAM_TABLE(X)                                                     \
    X(method, ENUM, "vaopp", 0, 0, OBS_CHOICES(OBS_METHOD_LIST),          \
      "AO method: vaopp (the VAO++ chain), vao (plain VAO, VAO++ section 3: "  \
      "adaptive, culling and range_check off), hemisphere (normal-oriented "   \
      "hemisphere SSAO), angle (angle-based paired-sample SSAO), hbao "        \
      "(horizon-based AO), gtao (ground-truth-based AO as XeGTAO implements "  \
      "it); every method shares the input, blur, luminance "    \
      "and composite; the others have no adaptive sampling, culling, range "   \
      "check or bleeding; a parameter of another method is refused")           \
    X(quality, ENUM, "default", 0, 0, OBS_CHOICES(OBS_QUALITY_LIST),           \
      "a preset that sets other parameters (a parameter given explicitly "     \
      "wins): preview (ao_resolution half), default (nothing), high "          \
      "(samples 32), reference (samples 32, adaptive off, culling off)")       \
    X(ao_resolution, ENUM, "full", 0, 0, OBS_CHOICES(OBS_RESOLUTION_LIST),     \
      "full: the AO of every pixel; half: of a quarter of them (half of each " \
      "axis), each a whole pixel of its 2x2 block (the nearest and the "      \
      "farthest in a checkerboard, never an average: both sides of a depth "   \
      "edge stay), blurred at that size, then upsampled to full size by a "    \
      "joint bilateral filter guided by the full-size depth and normals "      \
      "(bilinear weights times the cosine between the normals; a texel over "  \
      "the blur's depth threshold R away is left out). Not with bleeding or "  \
      "the sample_count/cull_mask outputs")                                    \
    X(radius, FLOAT, 0.5, 1e-4, 1e4, NULL,                                     \
      "AO distance D in world units, as in a ray tracer's AO (the fraction "  \
      "of cosine-weighted rays unblocked within D, Cycles' AO pass); VAO's "   \
      "kernel width R (below) follows from it by ao_definition: 2 D (rays) "   \
      "or D (volume)")                                                         \
    X(ao_definition, ENUM, "rays", 0, 0, OBS_CHOICES(OBS_AO_DEFINITION_LIST),                        \
      "what methods vaopp and vao return: rays, a ray tracer's AO within "    \
      "radius D: R = 2 D, so the tangent sphere (radius D) touches a wall "    \
      "exactly when rays of length D reach it, and eq 1's volume fraction is " \
      "converted to the fraction of unblocked cosine-weighted rays through "   \
      "a floor-wall crease, where both are known in closed form (occlusion "   \
      "over 1/2 unchanged; bench/QUALITY.md); volume: the paper's "            \
      "volumetric obscurance itself, R = D (tangent sphere of radius D/2)")    \
    X(samples, INT, 16, 2, 32, "2|4|8|16|32",                                  \
      "line samples per pixel on the tangent sphere's disk; the sets of "     \
      "VAO++ 4.5 (rotation-aware Poisson disk, best rotation permutation, "    \
      "z-order) exist for 2, 4, 8, 16 and 32 only, other counts are "          \
      "refused: the first n of a larger z-ordered set would cover one part "   \
      "of the disk")                                                           \
    X(adaptive, ENUM, "on", 0, 0, OBS_CHOICES(OBS_SWITCH_LIST),                                    \
      "adaptive sampling (VAO++ 4.1): each pixel takes the sample set whose "  \
      "size fits the area of its tangent sphere's disk projected on the "      \
      "screen: 2 samples up to twice the area of a disk of diameter "          \
      "adaptive_diameter, doubling with every doubling of the area, at most "  \
      "samples; off: every pixel takes samples")                               \
    X(adaptive_diameter, FLOAT, 0.01, 1e-4, 1.0, NULL,                         \
      "projected disk diameter, as a fraction of the image height, at which "  \
      "adaptive sampling uses its minimum of 2 samples (4x this diameter "     \
      "takes 32); 0.01 is 4.8 px at 480 px, where the 3x3 rotation tile's "    \
      "9 x 2 sample positions are as many as the pixels the disk covers")      \
    X(culling, ENUM, "careful", 0, 0, OBS_CHOICES(OBS_CULLING_LIST),                    \
      "culling pre-pass (VAO++ 4.2): AO with 8 samples at 1/8 resolution, "   \
      "read back at each pixel's four corners with bilinear filtering; a "     \
      "pixel where none of the four shows occlusion (estimate below 1 - "      \
      "culling_epsilon) is a culling candidate: greedy gives it AO 1, "        \
      "careful computes it with at most 4 samples; off: no pre-pass")         \
    X(culling_epsilon, FLOAT, 0.02, 1e-6, 0.5, NULL,                           \
      "a culling pre-pass estimate below 1 - culling_epsilon shows "           \
      "occlusion; 0.02 culls 48-79 % of the test scenes' pixels with a mean "  \
      "|AO(careful) - AO(off)| under 0.002 (half an 8-bit step)")              \
    X(depth_mode, ENUM, "planar", 0, 0, OBS_CHOICES(OBS_DEPTH_MODE_LIST),                   \
      "what the depth channel holds: distance along the camera axis, "         \
      "distance from the camera, a [0,1] OpenGL depth-buffer value, 1 / "      \
      "planar depth, or planar depth normalized to [0,1] between near and "    \
      "far (ndc and normalized take the camera's clip range; 0 (default): "   \
      "what the file's renderer preset says, else planar)")                   \
    X(normal_space, ENUM, "world", 0, 0, OBS_CHOICES(OBS_NORMAL_SPACE_LIST),                       \
      "space of the normal channel (world normals need world_to_camera; "     \
      "default: what the file's renderer preset says, else world)")          \
    X(unit_scale, FLOAT, 1.0, 1e-6, 1e6, NULL,                                 \
      "depth values are multiplied by this to reach the units of radius")      \
    X(fov_y, FLOAT, 0.0, 0.0, 179.0, NULL,                                     \
      "vertical field of view in degrees (0: take the camera from the EXR "    \
      "header or camera JSON)")                                                \
    X(fov_x, FLOAT, 0.0, 0.0, 179.0, NULL,                                     \
      "horizontal field of view in degrees, used when fov_y is 0")            \
    X(focal_length, FLOAT, 0.0, 0.0, 1e6, NULL,                               \
      "focal length (same unit as aperture), with aperture: the field of "    \
      "view when fov_y and fov_x are 0")                                       \
    X(aperture, FLOAT, 0.0, 0.0, 1e6, NULL,                                    \
      "horizontal film aperture (same unit as focal_length)")                 \
    X(near, FLOAT, 0.1, 1e-6, 1e9, NULL,                                       \
      "near clip distance, used with fov_y (ndc depth is linearised with it)") \
    X(far, FLOAT, 1000.0, 1e-6, 1e12, NULL,                                    \
      "far clip distance, used with fov_y")                                    \
    X(world_to_camera, MAT4, 0, 0, 0, NULL,                                    \
      "16 numbers, row-major, column-vector convention: world to camera "      \
      "(-Z forward); overrides the file's camera rotation")                    \
    X(range_check, ENUM, "on", 0, 0, OBS_CHOICES(OBS_SWITCH_LIST),                                 \
      "depth range check (VAO++ 4.4, eq 4): a pipe hidden behind a surface "   \
      "counts as occluded only by the falloff s(d) = u / max(u, d/R), "      \
      "d its distance behind that surface; off: occluders are infinitely "     \
      "thick")                                                                 \
    X(range_u, FLOAT, 0.03, 1e-4, 1.0, NULL,                                   \
      "u of the depth range check's falloff (eq 4): occluders are taken as "   \
      "fully thick up to u * R behind the visible surface")                    \
    X(range_distance, ENUM, "normal", 0, 0, OBS_CHOICES(OBS_RANGE_DISTANCE_LIST),                     \
      "how the depth range check measures eq 4's d, the distance of a pipe "  \
      "behind its occluder: normal: the pipe's depth below the occluding "     \
      "surface, along that surface's normal (d along view Z times |n.z| of "  \
      "the surface seen at the sample's pixel), the thickness of a flat "      \
      "occluder; view: along view Z (a floor seen at a grazing angle then "    \
      "counts as thin as a sheet facing the camera)")                          \
    X(blur, ENUM, "on", 0, 0, OBS_CHOICES(OBS_SWITCH_LIST),                                        \
      "low-pass filter (VAO++ 4.6): depth-aware cross-bilateral Gaussian "     \
      "blur of the AO, a horizontal then a vertical pass; neighbours whose "   \
      "view depth differs from the centre's by more than R are left out")      \
    X(blur_radius, INT, 2, 1, 16, NULL,                                        \
      "blur kernel half-width in pixels (the kernel is 2 * blur_radius + 1 "   \
      "taps per pass)")                                                        \
    X(blur_sigma, FLOAT, 1.25, 0.1, 64.0, NULL,                                \
      "standard deviation of the blur's Gaussian in pixels; with the default " \
      "radius 2, sigma 1.25 nulls the period-3 pattern of the 3x3 rotation "   \
      "tile (exp(-1/2s^2) + exp(-4/2s^2) = 1)")                                 \
    X(luminance, ENUM, "off", 0, 0, OBS_CHOICES(OBS_LUMINANCE_LIST),                           \
      "luminance sensitivity (VAO++ 4.3, eq 3): suppress the occlusion of "    \
      "bright pixels of the G-buffer colour, after the blur: occlusion 1 - AO "\
      "times (1 - min(1, max(0, lum - threshold + width)) / (2 width))^sigma, "\
      "lum the Rec. 709 luminance (lum) or HSV V = max(r, g, b) (value); "     \
      "off without a colour plane")                                            \
    X(lum_threshold, FLOAT, 0.5, 1e-4, 1e4, NULL,                               \
      "threshold of eq 3: the middle of the ramp from full to no occlusion "   \
      "(paper's Figure 9: 0.5)")                                               \
    X(lum_width, FLOAT, 0.3, 1e-3, 1e4, NULL,                                  \
      "width of eq 3: occlusion is untouched up to lum = threshold - width "   \
      "and gone from threshold + width (paper's Figure 9: 0.3); eq 3 as "      \
      "printed clamps lum - threshold + width at 1 before dividing by "        \
      "2 width, so above 0.5 some occlusion always stays")                     \
    X(lum_sigma, FLOAT, 1.0, 0.01, 100.0, NULL,                                \
      "sigma of eq 3, the ramp's linearity: 1 a straight ramp, above 1 "       \
      "occlusion falls off sooner, below 1 later")                             \
    X(bleeding, ENUM, "off", 0, 0, OBS_CHOICES(OBS_BLEEDING_LIST),                    \
      "colour bleeding (VAO++ 4.7, eq 5): the bleed term averages, over "      \
      "every sample (full), every second (half) or every fourth (quarter), "   \
      "white mixed towards the colour at the sample's pixel by c(x) = "        \
      "max(0, (x-p).n / |x-p|) max(0, 1 - |x-p|/R)^2, x the surface "          \
      "point seen there; the composite is multiplied by it; off without a "    \
      "colour plane")                                                          \
    X(hemisphere_samples, INT, 10, 1, 64, NULL,                                \
      "method hemisphere: samples in the normal-oriented hemisphere of "       \
      "radius D; Unity's post-processing stack (VAO++ Table 2) takes 3, 6, "   \
      "10 (its default, Medium) and 16")                                       \
    X(hemisphere_bias, FLOAT, 0.05, 1e-6, 1.0, NULL,                           \
      "method hemisphere: a sample is occluded when the surface at its pixel " \
      "lies more than hemisphere_bias * D in front of it (self-occlusion "     \
      "guard; 0.025 at radius 0.5 in the common kernel tutorials)")            \
    X(angle_pairs, INT, 6, 1, 16, NULL,                                        \
      "method angle: sample pairs per pixel, each pair two opposite points "   \
      "of a disk of radius D (6 in the angle-based SSAO article)")              \
    X(angle_acos, ENUM, "quadratic", 0, 0, OBS_CHOICES(OBS_ACOS_LIST),           \
      "method angle: the arc cosine of the pair angles: the article's "        \
      "quadratic pi (1 - sign(x) x^2) / 2 (max error 9.47 degrees), its "      \
      "linear pi (1 - x) / 2 (18.95 degrees), or exact acos")                  \
    X(hbao_directions, INT, 8, 1, 32, NULL,                                    \
      "method hbao: screen-space directions per pixel, Nd of HBAO (8 in "      \
      "NVIDIA's HBAO sample)")                                                 \
    X(hbao_steps, INT, 6, 1, 32, NULL,                                         \
      "method hbao: ray-marching steps per direction, Ns of HBAO (6 in "       \
      "NVIDIA's HBAO sample), spread over the projected radius D / (Ns + 1) "  \
      "apart")                                                                 \
    X(hbao_angle_bias, FLOAT, 30.0, 1e-6, 89.0, NULL,                          \
      "method hbao: angle bias in degrees added to the tangent angle t(theta) "\
      "against the self-occlusion of tessellated surfaces")                   \
    X(gtao_slices, INT, 3, 1, 32, NULL,                                        \
      "method gtao: slices (screen-space directions over pi, each searched "   \
      "both ways) per pixel; XeGTAO's presets take 1, 2, 3 (High, its "        \
      "default) and 9")                                                        \
    X(gtao_steps, INT, 3, 1, 32, NULL,                                         \
      "method gtao: horizon samples per side of a slice (XeGTAO: 2 to 3; "   \
      "on deep input with deep_intervals in effect 32, where the free-arc "    \
      "sum has converged)")                                                    \
    X(gtao_radius_multiplier, FLOAT, 1.457, 0.1, 4.0, NULL,                    \
      "method gtao: the search radius is gtao_radius_multiplier * D; 1.457 "   \
      "is XeGTAO's default, fitted by its authors to their ray-traced "        \
      "ground truth; 1 searches exactly the AO distance (the default on deep " \
      "input with deep_intervals in effect)")                                  \
    X(gtao_falloff, FLOAT, 0.615, 1e-6, 1.0, NULL,                             \
      "method gtao: a sample's weight falls linearly from 1 to 0 over the "    \
      "last gtao_falloff of the search radius (XeGTAO's EffectFalloffRange, "  \
      "0.615); near 0: a hard cut at the radius")                              \
    X(gtao_thin, FLOAT, 0.0, 0.0, 0.7, NULL,                                   \
      "method gtao: XeGTAO's thin-occluder compensation: the falloff reads "   \
      "the sample's depth offset scaled by 1 + gtao_thin, so samples far in "  \
      "depth fade sooner (XeGTAO's default 0)")                                \
    X(gtao_power, FLOAT, 2.2, 0.5, 5.0, NULL,                                  \
      "method gtao: the visibility is raised to this power (XeGTAO's "         \
      "FinalValuePower, 2.2); 1 leaves the slice integral as it is")          \
    X(gtao_heuristics, ENUM, "on", 0, 0, OBS_CHOICES(OBS_SWITCH_LIST),            \
      "method gtao: XeGTAO's three empirical corrections: the projected "      \
      "normal's length moved 5 % towards 1, a fade towards open for search "   \
      "radii under 10 pixels, visibility at least 0.03; off: the slice "       \
      "integral of Jimenez et al. as written")                                 \
    X(deep_mode, ENUM, "multi", 0, 0, OBS_CHOICES(OBS_DEEP_MODE_LIST),                          \
      "deep input: multi (OITAO Algorithm 1: each sample is occluded by every "\
      "compressed node at its pixel, the largest occlusion counts) or single " \
      "(the front node alone, as a flat depth buffer would)")                  \
    X(deep_layers, INT, 4, 1, 8, NULL,                                         \
      "deep input: nodes m kept per pixel by the list compression of OITAO "   \
      "III-B (eq 5 drops the node of least alpha (1 - z), z the depth "        \
      "normalised over the camera's clip range)")                              \
    X(deep_front_half, ENUM, "off", 0, 0, OBS_CHOICES(OBS_SWITCH_LIST),                            \
      "deep input: eq 5 searches the back half of the list only, keeping the " \
      "m/2 front nodes (OITAO V-A, Fig. 6 column C)")                          \
    X(deep_hull, ENUM, "solid", 0, 0, OBS_CHOICES(OBS_DEEP_HULL_LIST),                            \
      "deep input: transparent surfaces as solid volumes (OITAO eq 1: "        \
      "occluders and receivers weighted by alpha) or thin hulls (eqs 2-4: "    \
      "exterior and interior AO mixed by W(p), alpha or 1 - alpha on back "    \
      "faces)")                                                                \
    X(deep_intervals, ENUM, "auto", 0, 0, OBS_CHOICES(OBS_DEEP_INTERVALS_LIST), \
      "deep input with facing flags (channel Facing, as obscura gbuffer "      \
      "--deep writes), deep_mode multi, methods vaopp, vao and gtao: on, the " \
      "solid between a front face and its matching back face is an "           \
      "interval, free behind it, the list compression drops an interval's "   \
      "two faces together, and the depth range check applies only to a "       \
      "surface with no back face in the list (the obscured volume as it is; "  \
      "gtao: each slice's visibility over its free arcs, its parameters "      \
      "left unset taking the slice integral as written: "                      \
      "gtao_radius_multiplier 1, gtao_falloff 1e-6, gtao_power 1, "            \
      "gtao_heuristics off, gtao_steps 32); off, every node is solid behind "  \
      "it, as ao_definition rays' conversion and gtao's horizon assume "     \
      "(vaopp, vao, hemisphere: but a node inside a nearer node's "           \
      "interval, such as a back face, which adds nothing); auto "             \
      "(default): on for gtao, off for vaopp and vao, whose intervals "        \
      "measured farther from the ray tracer (bench/QUALITY.md, \"Deep input " \
      "against Cycles\")")                                                      \
    X(baked_combine, ENUM, "product", 0, 0, OBS_CHOICES(OBS_BAKED_COMBINE_LIST), \
      "--baked CH (HTTP: baked=CH): how the G-buffer's baked AO channel "      \
      "(obscura bake's _AO, rasterised by obscura gbuffer) is combined with "  \
      "the chain's AO: product (two visibility factors of separate scales, "   \
      "the baked distant obscurance times the screen-space detail) or min "    \
      "(the darker of the two: an occluder both see darkens once)")           \
    X(multibounce, ENUM, "off", 0, 0, OBS_CHOICES(OBS_SWITCH_LIST),             \
      "multi-bounce AO (Jimenez et al. 2016, the cubic fit): the AO's albedo-driven "  \
      "cubic fit of the light that bounces back into the occluded cone, "      \
      "max(A, ((a A + b) A + c) A), a, b, c linear in the albedo, per "        \
      "channel of the colour plane (name the albedo with --color albedo); "    \
      "on: the composite takes it and the AOMultiBounce.R,G,B layer is "       \
      "written beside the AO; a warning and the plain AO without a colour "    \
      "plane")                                                                 \
    X(receivers, STRING, "", 0, OBS_SELECTOR_MAX, NULL,                          \
      "object mask: the pixels that get AO, a selector (README: Object "       \
      "masks): Cryptomatte names with * and ? (any layer of the file; "        \
      "@LAYER: first for one), id:CHANNEL=N,N-M (integer ID channel) or "      \
      "matte:CHANNEL (coverage); a pixel of weight w gets 1 - w (1 - AO), "    \
      "anti-aliased edges by their Cryptomatte coverage; the rest stays 1 "    \
      "(Arnold's aiAmbientOcclusion on the selected shapes only); empty: all")\
    X(occluders, STRING, "", 0, OBS_SELECTOR_MAX, NULL,                          \
      "object mask: what may occlude, a selector as for receivers; a sample "  \
      "counts as occluding in proportion to the selected coverage of the "     \
      "surface it meets, an unselected one not at all (Arnold's trace_set "    \
      "with inclusive on); empty: everything")                                \
    X(self_only, ENUM, "off", 0, 0, OBS_CHOICES(OBS_SWITCH_LIST),              \
      "object mask: an object occludes only itself (Arnold's self_only): a "  \
      "sample counts only where the object seen at its pixel (the dominant "   \
      "Cryptomatte rank, or the ID channel, of the receivers or occluders "    \
      "selector, else the first Cryptomatte layer named *object*) is the "     \
      "shaded pixel's")

#define OBS__PDECL_FLOAT(n, hi) float n;
#define OBS__PDECL_INT(n, hi) int n;
#define OBS__PDECL_ENUM(n, hi) int n;
#define OBS__PDECL_MAT4(n, hi) float n[16];
#define OBS__PDECL_STRING(n, hi) char n[(hi) + 1];

typedef struct obs_params {
#define OBS__PDECL(name, type, def, lo, hi, choices, doc) OBS__PDECL_##type(name, hi)
    OBS_PARAM_TABLE(OBS__PDECL)
#undef OBS__PDECL
    int has_world_to_camera; /* set by obs_param_set for world_to_camera */
    /* Set by obs_params_resolve: 1 + the table index of the first
     * parameter the request gave that does not apply to its method
     * (obs_params_check refuses it, naming it); -1: none; 0: not resolved
     * yet.  Resolving a resolved struct again keeps it. */
    int method_conflict;
} obs_params;

/* A row of the table is the table engine's (obscura/table.h): name
 * (snake_case; flags use it with '-'), type, default as text, min and max
 * (FLOAT and INT), choices (ENUM "a|b|c"; INT: the numbers allowed), doc,
 * offsetof(obs_params, name). */
typedef obs_table_type obs_param_type;
#define OBS_PARAM_FLOAT OBS_TABLE_FLOAT
#define OBS_PARAM_INT OBS_TABLE_INT
#define OBS_PARAM_ENUM OBS_TABLE_ENUM
#define OBS_PARAM_MAT4 OBS_TABLE_MAT4
#define OBS_PARAM_STRING OBS_TABLE_STRING
typedef obs_table_row obs_param_info;

int obs_param_count(void);
/* NULL when i is out of range. */
const obs_param_info *obs_param_at(int i);
/* Finds a parameter by name; '-' and '_' are interchangeable. */
const obs_param_info *obs_param_find(const char *name);

/* Parses `value` for the parameter `name` into p, checking its range.
 * Errors name the parameter and the allowed values. */
obs_status obs_param_set(obs_params *p, const char *name, const char *value,
                         char err[OBS_ERR_LEN]);

/* Writes the value of parameter `pi` in p as text (the resolved value). */
void obs_param_format(const obs_params *p, const obs_param_info *pi, char *buf,
                      size_t len);

/* out = in with every zero field replaced by its default, then the
 * settings the method fixes: methods other than vaopp have adaptive
 * sampling, culling and the depth range check off (VAO++ features), and
 * methods hemisphere, angle, hbao and gtao have bleeding off too (it gathers the
 * colour at the VAO samples).  A parameter that in gave (non-zero) and
 * that the method does not use or fixes otherwise is recorded in
 * out->method_conflict; obs_params_check then refuses it. */
void obs_params_resolve(const obs_params *in, obs_params *out);

/* Checks every field of a resolved struct against the table's ranges;
 * the message names the first field out of range. */
obs_status obs_params_check(const obs_params *p, char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
