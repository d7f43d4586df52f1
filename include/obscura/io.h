/* Image I/O of libobscura: G-buffer EXR in (OpenEXR C API), EXR and PNG
 * out, camera JSON.  No GL here; safe to call from any thread. */
#ifndef OBSCURA_IO_H
#define OBSCURA_IO_H

#include <stddef.h>

#include "obscura/obscura.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- channel map -------------------------------------------------------- */

/* Which EXR channels hold depth, normal and colour.  A NULL/empty preset
 * means "auto": try blender, then generic.  Explicit names override the
 * preset's.  Channels are matched by name, never by position.
 *
 *   blender: depth ViewLayer.Depth.Z; normal ViewLayer.Normal.X/Y/Z;
 *            colour the beauty ViewLayer.Combined.R/G/B/A, else the albedo
 *            ViewLayer.DiffCol.R/G/B
 *   generic: depth Z (or depth.Z, Depth.Z); normal N.X/Y/Z or N.R/G/B
 *            (or normal.X/Y/Z, Normal.X/Y/Z); colour R/G/B/A
 *
 * color[0] "beauty" or "albedo" (the others NULL) asks for the preset's
 * beauty or diffuse albedo by name (an error when the file lacks it);
 * with no colour named, the beauty, else the albedo.  The colour plane is
 * what the composite multiplies by the AO (and what luminance and
 * bleeding read).
 */
typedef struct obs_channel_map {
    const char *preset;    /* "auto" (or NULL), "blender", "generic" */
    const char *depth;     /* explicit channel names, NULL = from preset */
    const char *normal[3];
    const char *color[4];  /* color[3] (alpha) may be NULL; or "beauty"/"albedo" */
    const char *part;      /* a part by name or index (NULL: by view, or the first part
                            * holding the depth) */
    const char *view;      /* a view of a multi-view, multi-part file (NULL: its default
                            * view); its parts' channels are gathered */
} obs_channel_map;

/* Valid preset names, NULL-terminated. */
extern const char *const obs_channel_presets[];

/* Most sanity warnings one read reports. */
#define OBS_EXR_WARNINGS 8

/* What the reader found, for logs and errors.  `warnings` are one line
 * each: the file looks unlike what its convention says (README.md,
 * "Sanity warnings"); --strict makes them errors. */
typedef struct obs_exr_info {
    int part;                  /* part index the channels were read from */
    int part_count;
    int tiled;
    const char *compression;   /* "zip", "piz", ... (static string) */
    char depth[64];            /* matched channel names ("" = absent) */
    char normal[3][64];
    char color[4][64];
    char position[3][64];      /* a world-space position pass ("" = none) */
    char preset[16];           /* preset that matched ("explicit" if none) */
    char view[64];             /* the view read ("" = the file has no views) */
    int parts_read;            /* parts the channels came from (1, or more for a view) */
    char renderer[16];         /* the renderer the header names ("" = none) */
    char renderer_why[96];     /* what in the header named it */
    obs_depth_mode depth_mode;     /* the preset's depth convention (0: not known) */
    obs_normal_space normal_space; /* the preset's normal space (0: not known) */
    char camera_source[160];   /* the attributes the camera came from ("" = none) */
    char camera_check[160];    /* cross-checks of the camera ("" = none made) */
    char camera_clip[64];      /* where the clip range came from ("" = default) */
    int camera_arnold;         /* 1: worldToNDC was in Arnold's convention */
    int warning_count;         /* sanity warnings (obs_exr_info.warnings) */
    char warnings[OBS_EXR_WARNINGS][224];
} obs_exr_info;

/* A G-buffer read from a file.  Frees with obs_gbuffer_free(). */
typedef struct obs_gbuffer_file {
    obs_gbuffer gb;    /* planes point into `storage` */
    float *storage;
    obs_exr_info info;
    float *mask_storage; /* the planes of obs_gbuffer_read_masks (obscura/mask.h) */
} obs_gbuffer_file;

/* Reads a G-buffer EXR (scanline or tiled, single or multipart, any
 * compression OpenEXR's C API decodes).  Honours the data window: the
 * G-buffer covers the data window.  The camera comes from the header's
 * worldToCamera/worldToNDC attributes when present.  Every size is checked
 * against `lim` (NULL = defaults) before anything is allocated.  The
 * chunks of the part are decoded by lim->threads threads (see
 * obs_limits); the result does not depend on the count. */
obs_status obs_gbuffer_read_exr(const char *path, const obs_channel_map *map,
                                const obs_limits *lim, obs_gbuffer_file *out,
                                char err[OBS_ERR_LEN]);

/* Same, from memory (the daemon reads request bodies this way).  `buf`
 * must stay valid during the call only. */
obs_status obs_gbuffer_read_exr_mem(const void *buf, size_t len,
                                    const obs_channel_map *map,
                                    const obs_limits *lim, obs_gbuffer_file *out,
                                    char err[OBS_ERR_LEN]);

/* Frees storage and zeroes *f; NULL-safe. */
void obs_gbuffer_free(obs_gbuffer_file *f);

/* A G-buffer EXR read by rows, for a frame that is never whole in memory
 * (obs_run_cpu_rows).  obs_gbuffer_rows_open reads the header and
 * resolves the channels as obs_gbuffer_read_exr does, no pixels: meta->gb
 * is the frame (size, windows, camera, conventions) with its planes' data
 * NULL and their channels set (1, 3 for normals, 4 for colour when the
 * file has them; no position pass), meta->info as the reader fills it.
 * A view whose channels lie in several parts is refused
 * (OBS_UNSUPPORTED).  Close with obs_gbuffer_rows_close(). */
typedef struct obs_gbuffer_rows obs_gbuffer_rows;
obs_status obs_gbuffer_rows_open(const char *path, const obs_channel_map *map, const obs_limits *lim,
                                 obs_gbuffer_rows **rows, obs_gbuffer_file *meta, char err[OBS_ERR_LEN]);

/* Rows [y0, y1) of the data window: *out is the frame with its planes'
 * data at row y0 (packed rows; rows outside the range are not there),
 * valid until the next read or the close.  Only the chunks holding those
 * rows are decoded (lim->threads threads). */
obs_status obs_gbuffer_rows_read(obs_gbuffer_rows *rows, int y0, int y1, obs_gbuffer *out,
                                 char err[OBS_ERR_LEN]);

/* Leaves the colour out of the reads from now on (a chain that reads no
 * colour: no composite, luminance, bleeding or multi-bounce), which
 * halves the bytes of a row with RGBA; the frame given to the chain must
 * then have no colour plane either. */
void obs_gbuffer_rows_no_color(obs_gbuffer_rows *rows);

/* NULL-safe. */
void obs_gbuffer_rows_close(obs_gbuffer_rows *rows);

/* The renderer, camera (and its source, cross-check and warnings) of part
 * `part` of an EXR, flat or deep, as the readers find them: fills those
 * fields of *info and *cam. */
obs_status obs_exr_describe_camera(const char *path, int part, obs_exr_info *info,
                                   obs_camera *cam, char err[OBS_ERR_LEN]);

/* The pinhole camera of a world-space position pass `pos` (3 floats a
 * pixel, the G-buffer's size; pixels with background depth are left out):
 * normalised DLT, Gauss-Newton refinement, then intrinsics and rotation.
 * A P no pinhole camera explains (RMS reprojection error over 0.5 px, an
 * affine or mirrored fit) is OBS_NO_CAMERA with the error in `err`.
 * *rms (may be NULL) receives the RMS reprojection error in pixels. */
obs_status obs_camera_solve_position(const obs_gbuffer *gb, const obs_plane *pos, obs_camera *cam,
                                     double *rms, char err[OBS_ERR_LEN]);

/* With no camera (none in the file, none in `params`: fov_y, fov_x or
 * focal_length with aperture), the camera solved from the file's position
 * pass (obs_camera_solve_position), its source and error in f->info; the
 * solver's refusal, or no position pass, is OBS_NO_CAMERA with a message.
 * With a camera, nothing (obs_gbuffer_sanity() checks it against P). */
obs_status obs_gbuffer_solve_camera(obs_gbuffer_file *f, const obs_params *params,
                                    char err[OBS_ERR_LEN]);

/* RMS and largest distance in pixels between each pixel centre and its
 * position projected by `cam`. */
obs_status obs_camera_reprojection(const obs_gbuffer *gb, const obs_plane *pos,
                                   const obs_camera *cam, double *rms, double *max_err,
                                   char err[OBS_ERR_LEN]);

/* One line a part, "INDEX 'NAME' (view VIEW): CH, CH, ...", into a newly
 * allocated, NULL-terminated array; caller frees with obs_strv_free(). */
obs_status obs_exr_describe_parts(const char *path, char ***lines, char err[OBS_ERR_LEN]);

/* Sanity checks of a G-buffer under the conventions `params` (NULL =
 * defaults) and the G-buffer's own give: depth all in 0..1 under a metric
 * depth mode, normals not unit length, normals that agree with the
 * normals derived from depth only in the other space or with the depth
 * inverted, and a camera whose reprojection of the position pass (when
 * the G-buffer has one) misses the pixel centres by more than a pixel
 * (RMS); depth values impossible for the depth mode (over 1 under ndc or
 * normalized), no geometry pixel, a radius under 1/1000 of the median
 * depth or above it; world-space normals without a world_to_camera
 * (said instead of the derived-normals comparison it invalidates).
 * Appends one line each to info->warnings; returns how many. */
int obs_gbuffer_sanity(const obs_gbuffer *gb, const obs_params *params, obs_exr_info *info);

/* The depth of a G-buffer's geometry as the chain reads it under the
 * depth mode of `params` (NULL = defaults) or the G-buffer's convention:
 * distance along the view axis (ndc and normalized converted with the
 * camera's clip range when it resolves). */
typedef struct obs_depth_range {
    long geometry;          /* pixels with a foreground depth */
    double min, median, max; /* over those pixels (0 when none) */
    long impossible;        /* ndc/normalized: values over 1 (and under the
                             * background marker) that no 0..1 depth holds */
    double impossible_max;
} obs_depth_range;
/* Fills *r; -1 when out of memory. */
int obs_gbuffer_depth_range(const obs_gbuffer *gb, const obs_params *params, obs_depth_range *r);

/* The radius to start from: the median depth over OBS_RADIUS_FRACTION.
 * At a 40-60 degree field of view a tenth of the viewing distance spans
 * about a tenth of the frame height, the scale of the contact shadows
 * AO is for; it also gives the default 0.5 on Blender's rooms, seen from
 * about 5 m (README.md, "Warnings").  0 without geometry. */
#define OBS_RADIUS_FRACTION 10.0
double obs_radius_suggest(const obs_depth_range *r);

/* The same over the front sample of each pixel of a deep image (its Z
 * is planar). */
struct obs_deep_image;
int obs_deep_depth_range(const struct obs_deep_image *d, obs_depth_range *r);

/* After a run: the AO of `gb` or `deep` (one may be NULL; the AO
 * image has its size, its background is AO 1) with no pixel occluded,
 * or a mean AO over the geometry above 0.99, is a warning that names the
 * radius, the depth range and the radius to start from; multibounce on
 * with no colour plane (or deep input) is a warning too (ao may then be
 * NULL).  Appends them to info->warnings; returns how many. */
int obs_result_sanity(const obs_image *ao, const obs_gbuffer *gb,
                      const struct obs_deep_image *deep, const obs_params *params,
                      obs_exr_info *info);

/* Reads one named channel of an EXR (any part that holds it) as float32;
 * for comparisons and tests.  Caller frees with obs_image_free(). */
obs_status obs_exr_read_channel(const char *path, const char *channel,
                                const obs_limits *lim, obs_image *out,
                                char err[OBS_ERR_LEN]);
/* The same from an EXR in memory (`len` bytes at data); messages name
 * it "EXR". */
obs_status obs_exr_read_channel_mem(const void *data, size_t len, const char *channel,
                                    const obs_limits *lim, obs_image *out,
                                    char err[OBS_ERR_LEN]);

/* Lists channel names of the first part into a newly allocated,
 * NULL-terminated array; caller frees with obs_strv_free(). */
obs_status obs_exr_list_channels(const char *path, char ***names,
                                 char err[OBS_ERR_LEN]);
void obs_strv_free(char **v);

/* ---- output ------------------------------------------------------------ */

typedef enum obs_exr_pixel {
    OBS_EXR_HALF,  /* default */
    OBS_EXR_FLOAT
} obs_exr_pixel;

/* An output EXR's compression (OpenEXR's names).  OBS_EXR_ZIP_DEFAULT
 * (zeroed options) is ZIP, the file default; the others are asked for by
 * name (obs_exr_compression_parse).  DWAA is lossy; it needs OpenEXR's C
 * API of 3.2 or later (obs_exr_compression_check). */
typedef enum obs_exr_compression {
    OBS_EXR_ZIP_DEFAULT,
    OBS_EXR_NONE,
    OBS_EXR_RLE,
    OBS_EXR_ZIPS,
    OBS_EXR_ZIP,
    OBS_EXR_PIZ,
    OBS_EXR_DWAA
} obs_exr_compression;

/* "none", "rle", "zips", "zip", "piz", "dwaa" (the default: "zip"). */
const char *obs_exr_compression_name(obs_exr_compression c);
/* The compression of that name; -1 when there is none. */
int obs_exr_compression_parse(const char *name);
/* OBS_OK when this build's OpenEXR writes and reads `c`; else
 * OBS_UNSUPPORTED and a message naming the compression and the library's
 * version. */
obs_status obs_exr_compression_check(obs_exr_compression c, char err[OBS_ERR_LEN]);

/* One image to store in an EXR under the given channel names
 * (names[c] for channel c of the image). */
typedef struct obs_exr_layer {
    const obs_image *image;
    const char *const *names;
} obs_exr_layer;

/* The layers of a result under obscura's channel names, in this order:
 * AO.Y; R,G,B,A (composite); Samples.Y (sample count); Cull.Y (culling
 * mask); Bleed.R,G,B; Luminance.Y; AOScreen.Y and AOBaked.Y (after
 * obs_result_combine_baked: the chain's AO and the baked channel; AO.Y
 * is then their combination); AOMultiBounce.R,G,B; BentNormal.X,Y,Z.  Fills `layers` with the images the result
 * holds; returns how many. */
#define OBS_RESULT_LAYERS 10
int obs_result_exr_layers(const obs_result *r, obs_exr_layer layers[OBS_RESULT_LAYERS]);

/* Writes a scanline EXR (ZIP compression) holding every layer's channels;
 * all images must have the same size.  When `cam` is non-NULL and has
 * a world_to_camera, worldToCamera and worldToNDC are written. */
obs_status obs_exr_write(const char *path, const obs_exr_layer *layers,
                         int layer_count, obs_exr_pixel pixel,
                         const obs_camera *cam, char err[OBS_ERR_LEN]);

/* The input an output EXR was computed from: its header goes with it. */
typedef struct obs_exr_source {
    const char *path;  /* the input file, or NULL and: */
    const void *buf;   /* the input in memory, `len` bytes */
    size_t len;
    int part;          /* the part the images were computed from
                        * (obs_exr_info.part, obs_deep_image.part) */
} obs_exr_source;

/* What an output says about how it was made (README.md, "Output
 * files").  Every EXR and PNG the library writes carries obscura/version
 * (OBS_VERSION); the fields given here add the other keys, each left out
 * when its field is NULL or empty:
 *   obscura/method         the method of `params` (resolved)
 *   obscura/params         its parameters that differ from the method's
 *                          defaults, "name=value" joined by spaces ("" for
 *                          none); `method` is among them when not vaopp
 *   obscura/input          `input`, e.g. the input file's path
 *   obscura/camera_source  `camera_source` (obs_exr_info.camera_source)
 * EXR: string attributes on the part the layers go to, in place of any
 * obscura/... the input's part carried (an earlier run's); the input's
 * own attributes, Software and the rest, are kept beside them.  PNG:
 * tEXt chunks (iTXt when a value is not ASCII).  The strings need only
 * live during the call. */
typedef struct obs_provenance {
    const obs_params *params; /* NULL: no obscura/method, obscura/params */
    const char *input;
    const char *camera_source;
    /* More string attributes, key, value, ..., NULL (at most 8 pairs; NULL:
     * none): obscura gbuffer --ids writes its Cryptomatte layer's here. */
    const char *const *attrs;
} obs_provenance;

/* How obs_exr_write_ex() writes.  Zeroed: half, no camera, no source,
 * the data window at the origin with the display window equal to it,
 * obscura/version the only provenance. */
typedef struct obs_exr_options {
    obs_exr_pixel pixel;
    /* worldToCamera / worldToNDC, written unless the source has its own */
    const obs_camera *cam;
    /* With a source, the output part takes its data window and display
     * window (the images must be the size of its data window) and every
     * header attribute of its part but the layout's (channels,
     * compression, windows, lineOrder, tiles, chunkCount, type, name,
     * version) and multiView (the output's channels are not the views'). */
    const obs_exr_source *src;
    /* With a source: the output is the input, every part and channel
     * (pixels unchanged, each channel in its own type), the layers added
     * to part src->part.  Parts are written as scanline parts, with the
     * input's compression where it is lossless (NONE, RLE, ZIPS, ZIP,
     * PIZ), else ZIP.  Refused (OBS_UNSUPPORTED) for deep parts. */
    int append;
    /* Without a source: the images' place in a display window, as in
     * obs_gbuffer (display_width 0: the display window is the images). */
    int display_x, display_y, display_width, display_height;
    /* obscura/... string attributes (NULL: obscura/version alone) */
    const obs_provenance *prov;
    /* The plain output's compression (zeroed: ZIP); append keeps the
     * input parts' own (above). */
    obs_exr_compression compression;
    /* Threads compressing chunks (0: the machine's cores, under the
     * process's limit); the bytes are the same for any count. */
    int threads;
} obs_exr_options;

/* A plain EXR output written by rows, for a frame never whole in memory
 * (obs_run_cpu_rows): obs_exr_rows_open writes the header of an image of
 * layers' width and `height` rows, layers' channels and names (the
 * images' rows are not written here; the names must live until the
 * close), as obs_exr_write_ex with `opt` (a source given by path, no
 * append; OBS_UNSUPPORTED otherwise); obs_exr_rows_write takes the next
 * rows, every layer's image holding the same count (written a batch of
 * chunks at a time, the same bytes as obs_exr_write_ex of the whole
 * image); obs_exr_rows_close finishes the file when st is OBS_OK and
 * every row came (else the file is removed, as a failed write's is) and
 * frees the writer; it returns the status. */
typedef struct obs_exr_rows obs_exr_rows;
obs_status obs_exr_rows_open(const char *path, const obs_exr_layer *layers, int layer_count, int height,
                             const obs_exr_options *opt, obs_exr_rows **out, char err[OBS_ERR_LEN]);
obs_status obs_exr_rows_write(obs_exr_rows *w, const obs_exr_layer *layers, int layer_count,
                              char err[OBS_ERR_LEN]);
obs_status obs_exr_rows_close(obs_exr_rows *w, obs_status st, char err[OBS_ERR_LEN]);

/* obs_exr_write() with options (NULL: as zeroed). */
obs_status obs_exr_write_ex(const char *path, const obs_exr_layer *layers, int layer_count,
                            const obs_exr_options *opt, char err[OBS_ERR_LEN]);

/* The layers renamed under one layer name, for --layer NAME: AO.Y
 * becomes NAME.Y, R,G,B,A NAME.R,G,B,A, any other channel C NAME.C.
 * The names live in `store`.  OBS_INVALID_ARGUMENT when NAME is empty,
 * over OBS_EXR_LAYER_MAX characters, starts or ends with '.', or holds a
 * control character. */
#define OBS_EXR_LAYER_MAX 63
typedef struct obs_exr_names {
    char name[OBS_RESULT_LAYERS * 4][OBS_EXR_LAYER_MAX + 32];
    const char *ptr[OBS_RESULT_LAYERS * 4];
} obs_exr_names;
obs_status obs_exr_layers_rename(obs_exr_layer *layers, int layer_count, const char *name,
                                 obs_exr_names *store, char err[OBS_ERR_LEN]);

/* The transfer function of a PNG's values, and the tag that says so
 * (README.md, "Output files").  Alpha is always linear. */
typedef enum obs_png_transfer {
    /* sRGB: the one Nuke's Read node (8- and 16-bit files are sRGB by
     * default, whatever the chunks say) and OpenImageIO (the sRGB chunk:
     * oiio:ColorSpace "sRGB") both read right */
    OBS_PNG_TRANSFER_DEFAULT,
    /* values sRGB-encoded (IEC 61966-2-1); sRGB chunk, with the gAMA
     * 1/2.2 and cHRM chunks the PNG spec asks of an sRGB encoder */
    OBS_PNG_TRANSFER_SRGB,
    /* values as computed; gAMA 1.0 with Rec. 709 cHRM, and cICP (Rec. 709
     * primaries, linear transfer, full range): OpenImageIO reads
     * oiio:ColorSpace "linear"; Nuke needs its Read set to linear */
    OBS_PNG_TRANSFER_LINEAR
} obs_png_transfer;

/* Valid --png-transfer names in enum order from 1 ("srgb", "linear"),
 * NULL-terminated; obs_png_transfer_parse() maps a name to its value
 * (OBS_PNG_TRANSFER_DEFAULT, 0, for an unknown one). */
extern const char *const obs_png_transfers[];
obs_png_transfer obs_png_transfer_parse(const char *name);

/* How obs_png_write_ex() writes.  Zeroed: 8 bit, sRGB, obscura/version
 * the only provenance. */
typedef struct obs_png_options {
    int bits;                  /* 8 or 16 (0: 8) */
    obs_png_transfer transfer; /* of the grey or colour channels */
    /* A colour image is display-referred: the sRGB transfer whatever
     * `transfer` says, and values over 1 brought into range without a
     * shift of hue (see obs_png_write_ex) */
    int display;
    const obs_provenance *prov; /* obscura/... text chunks (NULL: version) */
} obs_png_options;

/* Writes an 8- or 16-bit PNG: 1 channel -> grey, 3 -> RGB, 4 -> RGBA.
 * Values are clamped to [0,1] (NaN to 0), then encoded with the transfer
 * and tagged.  With `display`, an RGB(A) pixel whose largest colour
 * channel m is over 1 is scaled by 1/m before that (its hue and
 * saturation kept, where clamping each channel would turn an orange sky
 * yellow); pixels with every channel at most 1 are unchanged. */
obs_status obs_png_write_ex(const char *path, const obs_image *img, const obs_png_options *opt,
                            char err[OBS_ERR_LEN]);

/* obs_png_write_ex() with `bits`, the linear transfer (the values as
 * they are, tagged linear) and `display` = `srgb`: with `srgb` a colour
 * image is display-encoded, grey stays linear. */
obs_status obs_png_write(const char *path, const obs_image *img, int bits,
                         int srgb, char err[OBS_ERR_LEN]);

/* ---- in-memory output (the daemon answers with these) ------------------ */

/* Bytes owned by the library.  Caller frees with obs_bytes_free(). */
typedef struct obs_bytes {
    unsigned char *data; /* malloc'd; free() also releases it */
    size_t size;
} obs_bytes;

/* Frees the bytes and zeroes the struct; NULL-safe. */
void obs_bytes_free(obs_bytes *b);

/* obs_exr_write() into memory: the same file, byte for byte.  On success
 * *out holds the EXR; caller frees with obs_bytes_free(). */
obs_status obs_exr_write_mem(const obs_exr_layer *layers, int layer_count,
                             obs_exr_pixel pixel, const obs_camera *cam,
                             obs_bytes *out, char err[OBS_ERR_LEN]);

/* obs_exr_write_ex() into memory: the same file, byte for byte. */
obs_status obs_exr_write_ex_mem(const obs_exr_layer *layers, int layer_count, const obs_exr_options *opt,
                                obs_bytes *out, char err[OBS_ERR_LEN]);

/* obs_png_write() into memory: the same file, byte for byte.  On success
 * *out holds the PNG; caller frees with obs_bytes_free(). */
obs_status obs_png_write_mem(const obs_image *img, int bits, int srgb,
                             obs_bytes *out, char err[OBS_ERR_LEN]);

/* obs_png_write_ex() into memory: the same file, byte for byte. */
obs_status obs_png_write_ex_mem(const obs_image *img, const obs_png_options *opt, obs_bytes *out,
                                char err[OBS_ERR_LEN]);

/* ---- camera ------------------------------------------------------------ */

/* Reads a camera JSON (width, height, fov_y_deg, near, far,
 * world_to_camera, projection: 4x4 row-major, column-vector convention)
 * into *cam.  `width`/`height` receive the JSON's image size (0 if
 * absent); either may be NULL. */
obs_status obs_camera_read_json(const char *path, obs_camera *cam, int *width,
                                int *height, char err[OBS_ERR_LEN]);

/* A perspective camera from a vertical field of view (degrees), the image
 * aspect and clip range; world_to_camera is identity. */
void obs_camera_from_fov(float fov_y_deg, float aspect, float near_z,
                         float far_z, obs_camera *cam);

/* A camera whose matrices a request carried (the binary protocol's raw
 * and deep frames, already in *cam): which of them it has, and its source
 * (OBS_CAMERA_PARAMS with a projection, OBS_CAMERA_NONE without). */
void obs_camera_from_request(obs_camera *cam, int has_world_to_camera, int has_projection);

/* The camera a frame of gb runs with under p: the G-buffer's, its
 * projection and world_to_camera overridden by the parameters' (fov_y,
 * fov_x or focal_length with aperture; world_to_camera), as the chain
 * resolves it.  An output takes its worldToCamera/worldToNDC from it, so
 * that the camera given as parameters (HTTP's query, obscura ao
 * --fov-y --world-to-camera) is written as a camera JSON's is.  1 with
 * *out when it has a projection, else 0. */
int obs_camera_of_run(const obs_gbuffer *gb, const obs_params *p, obs_camera *out);

/* Fits a centred perspective projection to an image of width x height:
 * the vertical field of view stays, the horizontal one follows the aspect
 * (x scale = y scale * height / width).  Returns 1 when it changed the
 * projection, 0 when the projection is not a centred perspective (an
 * off-centre or orthographic one is left as it is) or already fits. */
int obs_camera_fit_aspect(obs_camera *cam, int width, int height);

#ifdef __cplusplus
}
#endif

#endif
