/* obscura: the command-line client.  Runs the AO chain in-process.
 *
 *   obscura ao IN.exr -o OUT.(exr|png) [options] [parameters]
 *   obscura compare TRUTH.exr CANDIDATE.exr [--channel-a CH] [--channel-b CH] ...
 *   obscura info [--backend B]
 *   obscura params [--markdown]
 *   obscura samples [--c]
 *   obscura gbuffer SCENE -o OUT.exr --camera CAM.json   (clients/ground.c)
 *   obscura reference SCENE -o REF.exr --camera CAM.json (clients/ground.c)
 *   obscura batch IN.####.exr --frames 1-100x2 -o OUT.####.exr [--server URL] [--jobs N] [--allow-missing] ...
 *
 * Exit codes: 0 ok, 1 failure (GL, I/O), 2 usage, 3 bad input. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "batch.h"
#include "obscura/deep.h"
#include "cli.h"
#include "flags.h"
#include "inspect.h"
#include "bake.h"
#include "dynamic.h"
#include "ground.h"
#include "obscura/io.h"
#include "obscura/mask.h"
#include "obscura/metrics.h"
#include "obscura/obscura.h"
#include "remote.h"
#include "warmup.h"


static int verbosity = OBS_LOG_INFO;

/* obscura batch runs cmd_ao once per frame and keeps one context. */
static int keep_ctx;
static obs_ctx *kept_ctx;

static void log_cb(void *user, obs_log_level level, const char *msg)
{
    static const char *const names[] = {"error", "warning", "info", "debug"};
    (void)user;
    if ((int)level <= verbosity)
        fprintf(stderr, "obscura: %s: %s\n", names[level], msg);
}

static void die_usage(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "obscura: error: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(run 'obscura help' for usage)\n");
    va_end(ap);
    exit(EXIT_USAGE);
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

/* ---- options ------------------------------------------------------------- */

/* Options of the client itself; the AO parameters come from the one
 * parameter table (obs_param_*), so they are not listed here. */
typedef struct cli_opt {
    const char *name; /* without "--" */
    const char *arg;  /* NULL: a switch */
    const char *doc;
} cli_opt;

static const cli_opt ao_opts[] = {
    {"o", "FILE", "output file; .exr or .png (also --output-file)"},
    {"output", "ao|composite|both|samples|cull|bleed|luminance|multibounce|bent|aovs|deep",
     "what to write (default ao); a comma list combines them; deep (deep input, EXR, alone): "
     "the AO of every kept node as a deep EXR with the flat AO beside it; bent: the bent normal "
     "in the normals' space (method gtao; EXR channels BentNormal.X/Y/Z, PNG 0.5 + 0.5 n); aovs: the AO, the multi-bounce "
     "AO and the sample count in one EXR, the layers of README's AOV table (with --append, in "
     "the input's own file); multibounce: the AO through the albedo-driven multi-bounce fit "
     "(Jimenez et al. 2016, --multibounce; EXR channels AOMultiBounce.R/G/B); samples: the sample count "
     "of each pixel (adaptive sampling, VAO++ 4.1; EXR channel Samples.Y, PNG count/32); "
     "cull: 1 where the culling pre-pass culled the pixel (VAO++ 4.2; EXR channel Cull.Y); "
     "bleed: the colour-bleed term (VAO++ 4.7, --bleeding; EXR channels Bleed.R/G/B); "
     "luminance: the factor of VAO++ eq 3 (4.3, --luminance), 1 keeps the occlusion, 0 "
     "removes it (EXR channel Luminance.Y)"},
    {"format", "exr|png", "output format (default: from the file name)"},
    {"float", NULL, "EXR: 32-bit float channels (default half)"},
    {"png-bits", "8|16", "PNG bit depth (default 8)"},
    {"camera", "FILE", "camera JSON (width, height, fov_y_deg, world_to_camera, projection)"},
    {"preset", "P", "renderer preset: auto (default: from the header), blender, generic, arnold, "
     "vray, renderman, redshift, karma, mantra, octane, nuke"},
    {"strict", NULL, "sanity warnings on the input are errors (exit 3)"},
    {"solve-camera", NULL, "no camera given or in the file: solve it from the position pass"},
    {"depth", "CH", "depth channel name"},
    {"normal", "X,Y,Z", "normal channel names"},
    {"color", "beauty|albedo|R,G,B[,A]", "the colour plane: the beauty (default), the albedo, or channel names"},
    {"baked", "CH|none", "a baked AO channel of the input (obscura gbuffer of a level baked by "
     "obscura bake: _AO, _AO_SHORT, _AO_LONG; default _AO when the input has it) combined with "
     "the chain's AO (--baked-combine, default product): AO.Y is the combination, "
     "AOScreen.Y the chain's, AOBaked.Y the channel; none: not combined"},
    {"max-size", "N", "largest accepted width or height (default 16384)"},
    {"backend", "B", "auto|cpu|egl-device|egl-surfaceless|osmesa (or OBSCURA_BACKEND); cpu: the "
     "chain on the CPU device (every core, SIMD), no GL context; auto: a GPU, else the faster of cpu "
     "and llvmpipe, measured once and kept in the cache folder"},
    {"cache-dir", "DIR", "program cache folder (or OBSCURA_CACHE_DIR; default "
     "$XDG_CACHE_HOME/obscura, else ~/.cache/obscura; '': none)"},
    {"cpu", NULL, "the same as --backend cpu"},
    {"threads", "N", "the threads this process may run, 1..64 (or OBSCURA_THREADS; default every "
     "core): llvmpipe's (LP_NUM_THREADS, unless set) and every worker pool's"},
    {"max-memory", "MIB", "the memory a frame on the CPU device may hold, in MiB (or "
     "OBSCURA_MAX_MEMORY; default a quarter of the usable memory): over it the frame runs in bands of "
     "rows, the same result (README \"Frames larger than memory\")"},
    {"server", "URL[,URL...]", "run on obscurad: http://HOST:PORT, unix:/PATH or tcp://HOST:PORT; a "
     "comma list spreads frames over several (the next one when one is busy or down)"},
    {"stream", "NAME", "with an http:// --server: post the frame to the daemon's stream NAME too "
     "(the preview page at the daemon's / shows it)"},
    {"debug-gl", NULL, "install the KHR_debug callback and log GL messages"},
    {"quiet", NULL, "only warnings and errors (-q)"},
    {"verbose", NULL, "debug messages too (-v)"},
    {NULL, NULL, NULL}};

/* Each command's usage lines: `obscura help` prints them all, `obscura
 * COMMAND --help` its own. */
static const struct {
    const char *cmd, *text;
} usage_lines[] = {
    {"ao", "  obscura ao IN.exr -o OUT.(exr|png) [options] [parameters]\n"
           "                  IN '-': the EXR from stdin; OUT '-': to stdout (needs --format)\n"},
    {"compare", "  obscura compare TRUTH.exr CANDIDATE.exr [--channel-a CH] [--channel-b CH]\n"
                "                  [--mask auto|none|CH] [--diff OUT.(png|exr)] [--json]\n"
                "                  metrics: MSE, PSNR, SSIM, MAE, corr, bias over the mask's pixels;\n"
                "                  --mask auto: where TRUTH's (else CANDIDATE's) depth channel has\n"
                "                  geometry (0 < Z < 1e9); none: every pixel; CH: where channel CH of\n"
                "                  TRUTH is a depth with geometry\n"},
    {"inspect", "  obscura inspect IN.exr [--json] [--preset P] [--depth-mode M] ...\n"
                "                  what obscura reads: renderer, channels, camera and its source,\n"
                "                  conventions, windows, part, sanity warnings\n"},
    {"info", "  obscura info [--backend B] [--threads N] [--max-memory MIB]\n"},
    {"params", "  obscura params [--markdown]\n"},
    {"samples", "  obscura samples [--c]            the sample sets (VAO++ 4.5); --c: as "
                "core/chain/sample_tables.c\n"},
    {"batch", "  obscura batch IN.####.exr --frames SPEC -o OUT.####.exr [--server URL] [--jobs N]\n"
              "                [--allow-missing] [--progress plain|percent] [-q] [ao options]\n"
              "                a frame sequence; SPEC 1-100, 1-100x2, 1,5,9; #### or %04d is the frame;\n"
              "                a missing input is exit 3, the others still written (--allow-missing:\n"
              "                exit 0, unless nothing was written); percent: 'Progress: N%' on stdout;\n"
              "                -q: no line per frame\n"},
};

/* A parameter's flag: --name with '-' for '_'. */
static void param_flag(const obs_param_info *pi, char *flag, size_t len)
{
    snprintf(flag, len, "--%s", pi->name);
    for (char *c = flag; *c; c++)
        if (*c == '_')
            *c = '-';
}

/* A parameter's range, its choices or its bounds, as --help writes it
 * (" {CHOICES}", " [LO..HI]") or as the parameter table does (table:
 * "CHOICES", "LO .. HI", a text's "at most MAX bytes"); "" when it has
 * none. */
static void param_range(const obs_param_info *pi, int table, char *range, size_t len)
{
    range[0] = 0;
    if ((pi->type == OBS_PARAM_INT && pi->choices) || pi->type == OBS_PARAM_ENUM)
        snprintf(range, len, table ? "%s" : " {%s}", pi->choices);
    else if (pi->type == OBS_PARAM_FLOAT || pi->type == OBS_PARAM_INT)
        snprintf(range, len, table ? "%g .. %g" : " [%g..%g]", pi->min, pi->max);
    else if (pi->type == OBS_PARAM_STRING && table)
        snprintf(range, len, "at most %g bytes", pi->max);
}

/* The ao options and the parameter table; the left column widens to
 * the longest entry's line of its own, so no entry is cut. */
static void usage_ao_options(FILE *f)
{
    fprintf(f, "\nao options:\n");
    for (const cli_opt *o = ao_opts; o->name; o++) {
        char left[128];
        snprintf(left, sizeof left, "%s%s %s", o->name[1] ? "--" : "-", o->name, o->arg ? o->arg : "");
        if (strlen(left) > 30) /* its own line, the doc under it */
            fprintf(f, "  %s\n  %-30s %s\n", left, "", o->doc);
        else
            fprintf(f, "  %-30s %s\n", left, o->doc);
    }
    fprintf(f, "\nparameters (the one parameter table; 'obscura params' for details):\n");
    for (int i = 0; i < obs_param_count(); i++) {
        const obs_param_info *pi = obs_param_at(i);
        char flag[80], range[256];
        param_flag(pi, flag, sizeof flag);
        param_range(pi, 0, range, sizeof range);
        fprintf(f, "  %-30s %s (default %s%s)\n", flag, pi->doc, pi->def, range);
    }
}

static const char exit_codes[] =
    "\nexit codes: 0 ok, 1 failure, 2 usage, 3 bad input (batch: also a missing frame, or\n"
    "nothing written), 4 server unreachable or busy\n";

/* Every command but params and samples takes --threads (main: cli_take_threads). */
static const char threads_note[] =
    "\n--threads N (or OBSCURA_THREADS), on every command but params and samples: the threads\n"
    "this process may run, 1..64 (default every core): llvmpipe's (LP_NUM_THREADS, unless set)\n"
    "and every worker pool's (the bakes' threads parameter is the same setting)\n";

static void usage(FILE *f)
{
    fprintf(f, "obscura %s: ambient occlusion for G-buffer EXRs (VAO on OpenGL)\n\nusage:\n", OBS_VERSION);
    for (size_t i = 0; i < sizeof usage_lines / sizeof *usage_lines; i++)
        fputs(usage_lines[i].text, f);
    cli_ground_usage(f);
    cli_warmup_usage(f);
    cli_bake_usage(f);
    cli_dynamic_usage(f);
    usage_ao_options(f);
    fputs(threads_note, f);
    fputs(exit_codes, f);
}

/* `obscura COMMAND --help`: that command's lines (ao and batch: with the
 * ao options); 0 when cmd is no command. */
static int usage_of(FILE *f, const char *cmd)
{
    fprintf(f, "usage:\n");
    for (size_t i = 0; i < sizeof usage_lines / sizeof *usage_lines; i++)
        if (!strcmp(cmd, usage_lines[i].cmd)) {
            fputs(usage_lines[i].text, f);
            if (!strcmp(cmd, "ao") || !strcmp(cmd, "batch"))
                usage_ao_options(f); /* --threads is one of them */
            else if (strcmp(cmd, "params") && strcmp(cmd, "samples"))
                fputs(threads_note, f);
            fputs(exit_codes, f);
            return 1;
        }
    if (!strcmp(cmd, "gbuffer") || !strcmp(cmd, "reference"))
        cli_ground_usage(f);
    else if (!strcmp(cmd, "warmup"))
        cli_warmup_usage(f);
    else if (!strcmp(cmd, "bake"))
        cli_bake_usage(f);
    else if (!strcmp(cmd, "bake-dynamic"))
        cli_dynamic_usage(f);
    else
        return 0;
    fputs(threads_note, f);
    fputs(exit_codes, f);
    return 1;
}

/* The request options (output, format, float, png_bits, the channel
 * map) live in req, parsed by their rows in protocol/http.c; the rest are
 * the client's own. */
typedef struct ao_args {
    const char *in, *out, *camera, *backend, *cache_dir;
    unsigned char *in_buf; /* IN '-': stdin's bytes (in_len), read once */
    size_t in_len;
    int to_stdout;         /* -o - */
    int format_given; /* else the format comes from the file name */
    int cpu, debug_gl;
    long max_size;
    obs_http_request req;
} ao_args;

/* An unknown option: a usage error, with the nearest of the ao options
 * and the parameter table's names when one is at most two edits away
 * ("--radiu": did you mean --radius?). */
static void die_unknown_option(const char *arg)
{
    char shown[256];
    cli_suggest sg;
    cli_suggest_start(&sg, arg);
    for (const cli_opt *o = ao_opts; o->name; o++)
        cli_suggest_try(&sg, o->name);
    for (int k = 0; k < obs_param_count(); k++)
        cli_suggest_try(&sg, obs_param_at(k)->name);
    cli_escape(arg, shown, sizeof shown);
    if (sg.best[0])
        die_usage("unknown option '%s'; did you mean %s?", shown, sg.best);
    die_usage("unknown option '%s'", shown);
}

/* Matches "--name VALUE" or "--name=VALUE"; returns the value or NULL. */
static const char *opt_value(int argc, char **argv, int *i, const char *name)
{
    const char *v = NULL;
    if (cli_flag_value(argc, argv, i, name, &v) < 0)
        die_usage("option --%s needs a value", name);
    return v;
}

static void parse_ao(int argc, char **argv, ao_args *a)
{
    const char *v;
    const obs_http_option *op;
    char err[OBS_ERR_LEN];
    int k;
    memset(a, 0, sizeof *a);
    obs_http_request_init(&a->req);
    for (int i = 0; i < argc; i++) {
        const char *arg = argv[i];
        if (arg[0] != '-' || arg[1] == '\0') {
            if (a->in)
                die_usage("more than one input file ('%s' and '%s')", a->in, arg);
            a->in = arg;
        } else if ((v = opt_value(argc, argv, &i, "o")) || (v = opt_value(argc, argv, &i, "output-file"))) {
            a->out = v;
        } else if ((k = cli_request_flag(argc, argv, &i, &a->req, &op, err)) != 0) {
            if (k < 0)
                die_usage("%s", err);
            a->format_given |= !strcmp(op->name, "format");
            /* The flags below have no request option, so they stay the
             * CLI's: the camera JSON is sent as parameters (remote.c), the
             * size limit and the backend are obscurad's own configuration,
             * and the rest are this process's. */
        } else if ((v = opt_value(argc, argv, &i, "camera"))) {
            a->camera = v;
        } else if ((v = opt_value(argc, argv, &i, "max-size"))) {
            a->max_size = strtol(v, NULL, 10);
            if (a->max_size < 1 || a->max_size > 1 << 20)
                die_usage("--max-size: '%s' is not in [1, 1048576]", v);
        } else if ((v = opt_value(argc, argv, &i, "backend"))) {
            a->backend = v;
        } else if ((v = opt_value(argc, argv, &i, "cache-dir"))) {
            a->cache_dir = v;
        } else if (cli_is_switch(arg, "cpu")) {
            a->cpu = 1;
        } else if (cli_is_switch(arg, "debug-gl")) {
            a->debug_gl = 1;
        } else if (cli_is_switch(arg, "quiet") || !strcmp(arg, "-q")) {
            verbosity = OBS_LOG_WARN;
        } else if (cli_is_switch(arg, "verbose") || !strcmp(arg, "-v")) {
            verbosity = OBS_LOG_DEBUG;
        } else if (arg[1] == '-') {
            /* a parameter of the table: --name VALUE or --name=VALUE */
            char name[64];
            const char *eq = strchr(arg + 2, '=');
            size_t n = eq ? (size_t)(eq - arg - 2) : strlen(arg + 2);
            snprintf(name, sizeof name, "%.*s", (int)n, arg + 2);
            if (!obs_param_find(name))
                die_unknown_option(arg);
            if (!eq && i + 1 >= argc)
                die_usage("parameter --%s needs a value", name);
            if (obs_param_set(&a->req.params, name, eq ? eq + 1 : argv[++i], err) != OBS_OK)
                die_usage("%s", err);
        } else {
            die_unknown_option(arg);
        }
    }
    if (!a->in)
        die_usage("ao: no input file");
    if (!a->out)
        die_usage("ao: no output file (-o FILE)");
    a->to_stdout = !strcmp(a->out, "-");
    if (a->to_stdout && !a->format_given)
        die_usage("ao: -o - writes to stdout, which has no file name to tell the format from: add "
                  "--format exr or --format png");
    if (!a->format_given) {
        const char *dot = strrchr(a->out, '.');
        if (dot && !strcmp(dot, ".png"))
            a->req.format = OBS_HTTP_PNG;
        else if (dot && !strcmp(dot, ".exr"))
            a->req.format = OBS_HTTP_EXR;
        else
            die_usage("cannot tell the format of '%s': use .exr or .png, or --format", a->out);
    }
    if (a->to_stdout && a->req.format == OBS_HTTP_PNG && (a->req.outputs & (a->req.outputs - 1)))
        die_usage("ao: -o - writes one file to stdout, and these outputs are several PNGs: use --format exr "
                  "(one file with every output), or a file name");
    if (a->req.format != OBS_HTTP_EXR && (a->req.append || a->req.layer))
        die_usage("--%s names the channels of an EXR: the output '%s' is a PNG", a->req.append ? "append" : "layer",
                  a->out);
    obs_exr_names names;
    if (a->req.layer && obs_exr_layers_rename(NULL, 0, a->req.layer, &names, err) != OBS_OK)
        die_usage("--layer: %s", err);
    if (obs_exr_compression_check((obs_exr_compression)a->req.compression, err) != OBS_OK)
        die_usage("--compression: %s", err);
}

/* -o -: a whole file to stdout (oiiotool's convention). */
static obs_status put_stdout(const obs_bytes *b, char err[OBS_ERR_LEN])
{
    if (fwrite(b->data, 1, b->size, stdout) != b->size || fflush(stdout) != 0) {
        snprintf(err, OBS_ERR_LEN, "cannot write to stdout: %s", strerror(errno));
        return OBS_IO;
    }
    return OBS_OK;
}

/* A whole file as it is (the daemon's deep EXR answer). */
static obs_status put_file(const char *path, const obs_bytes *b, char err[OBS_ERR_LEN])
{
    FILE *fp = fopen(path, "wb");
    int ok = fp && fwrite(b->data, 1, b->size, fp) == b->size;
    if (fp && fclose(fp) != 0)
        ok = 0;
    if (!ok) {
        snprintf(err, OBS_ERR_LEN, "cannot write it: %s", strerror(errno));
        return OBS_IO;
    }
    return OBS_OK;
}

/* A PNG of `obscura ao` to its file, or to stdout under -o -. */
static obs_status write_png_out(const ao_args *a, const char *path, const obs_image *img,
                                const obs_png_options *po, char err[OBS_ERR_LEN])
{
    if (!a->to_stdout)
        return obs_png_write_ex(path, img, po, err);
    obs_bytes b = {0};
    obs_status s = obs_png_write_ex_mem(img, po, &b, err);
    if (s == OBS_OK)
        s = put_stdout(&b, err);
    obs_bytes_free(&b);
    return s;
}

/* -o - holds one image: several PNGs need files (an EXR holds them all). */
static obs_status one_png_for_stdout(const ao_args *a, int count, char err[OBS_ERR_LEN])
{
    if (!a->to_stdout || count <= 1)
        return OBS_OK;
    snprintf(err, OBS_ERR_LEN, "-o - writes one file to stdout, and these outputs are %d PNGs: use "
             "--format exr (one file with every output), or a file name", count);
    return OBS_INVALID_ARGUMENT;
}

/* What every output says of its making: the version (the writers add it),
 * the method and the non-default parameters.  The input's path and the
 * camera's source are left out on purpose: one frame run in process or
 * through any transport gives the same bytes, which the daemon could not
 * keep with a path only the CLI knows. */
static obs_provenance provenance_of(const ao_args *a)
{
    return (obs_provenance){.params = &a->req.params};
}

/* An EXR of `obscura ao`: the input's windows and header attributes
 * kept (from part `part`, the one read), under --layer's names, the
 * input itself with the AO added under --append. */
static obs_status write_exr_out(const ao_args *a, obs_exr_layer *layers, int n, const obs_camera *cam, int part,
                                char err[OBS_ERR_LEN])
{
    obs_exr_source src = {.path = a->in_buf ? NULL : a->in, .buf = a->in_buf, .len = a->in_len, .part = part};
    obs_provenance prov = provenance_of(a);
    obs_exr_options o = {.pixel = a->req.float_exr ? OBS_EXR_FLOAT : OBS_EXR_HALF, .cam = cam, .src = &src,
                         .append = a->req.append, .prov = &prov,
                         .compression = (obs_exr_compression)a->req.compression};
    obs_exr_names names;
    obs_status s = OBS_OK;
    if (a->req.layer && (s = obs_exr_layers_rename(layers, n, a->req.layer, &names, err)) != OBS_OK)
        return s;
    if (!a->to_stdout)
        return obs_exr_write_ex(a->out, layers, n, &o, err);
    obs_bytes b = {0};
    if ((s = obs_exr_write_ex_mem(layers, n, &o, &b, err)) == OBS_OK)
        s = put_stdout(&b, err);
    obs_bytes_free(&b);
    return s;
}

/* 1 when the outputs are written as a half EXR as the chain gives them:
 * a daemon's half answer then writes the same file (--server). */
static int half_answer(const ao_args *a)
{
    return a->req.format == OBS_HTTP_EXR && !a->req.float_exr;
}

/* "dir/out.png" + "ao" -> "dir/out.ao.png"; a frame number stays last,
 * where sequence readers look for it: "comp.0001.png" -> "comp.ao.0001.png". */
static void suffixed(const char *path, const char *suffix, char *buf, size_t len)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    if (!dot || dot < base)
        dot = path + strlen(path);
    const char *num = dot;
    while (num > base && num[-1] >= '0' && num[-1] <= '9')
        num--;
    if (num < dot && num > base + 1 && num[-1] == '.') /* NAME.FRAME.ext */
        snprintf(buf, len, "%.*s%s.%.*s", (int)(num - path), path, suffix, (int)(strlen(num)), num);
    else
        snprintf(buf, len, "%.*s.%s%s", (int)(dot - path), path, suffix, dot);
}

/* An image into [0, 1] for PNG: the sample count as count / 32, the bent
 * normal as 0.5 + 0.5 n. */
static obs_status png_scaled(const obs_image *img, float scale, float offset, obs_image *out)
{
    size_t n = (size_t)img->width * img->height * img->channels;
    out->data = malloc(n * sizeof(float));
    if (!out->data)
        return OBS_NO_MEMORY;
    out->width = img->width;
    out->height = img->height;
    out->channels = img->channels;
    for (size_t i = 0; i < n; i++)
        out->data[i] = offset + scale * img->data[i];
    return OBS_OK;
}

static obs_status write_outputs(const ao_args *a, const obs_result *r, const obs_camera *cam, int part,
                                char err[OBS_ERR_LEN])
{
    obs_provenance prov = provenance_of(a);
    obs_status s = OBS_OK;
    if (a->req.format == OBS_HTTP_EXR) {
        obs_exr_layer layers[OBS_RESULT_LAYERS];
        int n = obs_result_exr_layers(r, layers);
        s = write_exr_out(a, layers, n, cam, part, err);
        if (s == OBS_OK && verbosity >= OBS_LOG_INFO)
            fprintf(stderr, "obscura: wrote %s\n", a->out);
        return s;
    }
    /* PNG: one file per output; NAME.ao.png, NAME.composite.png,
     * NAME.samples.png, NAME.cull.png, NAME.bleed.png, NAME.luminance.png,
     * NAME.screen.png, NAME.baked.png, NAME.multibounce.png, NAME.bent.png
     * when there are several */
    /* AO images take --png-transfer; data (counts, masks, factors) stays
     * linear; colour is display-encoded */
    enum { DATA, AO, DISPLAY };
    const struct {
        const obs_image *img;
        const char *suffix;
        int kind;
    } files[] = {{&r->ao, "ao", AO},
                 {&r->composite, "composite", DISPLAY},
                 {&r->sample_count, "samples", DATA},
                 {&r->cull_mask, "cull", DATA},
                 {&r->bleed, "bleed", DISPLAY},
                 {&r->luminance, "luminance", DATA},
                 {&r->ao_screen, "screen", AO},
                 {&r->ao_baked, "baked", AO},
                 {&r->multibounce, "multibounce", AO},
                 {&r->bent, "bent", DATA}};
    int count = !!r->ao.data + !!r->composite.data + !!r->sample_count.data + !!r->cull_mask.data +
                !!r->bleed.data + !!r->luminance.data + !!r->ao_screen.data + !!r->ao_baked.data +
                !!r->multibounce.data + !!r->bent.data;
    if ((s = one_png_for_stdout(a, count, err)) != OBS_OK)
        return s;
    for (size_t k = 0; k < sizeof files / sizeof files[0] && s == OBS_OK; k++) {
        char path[4096];
        obs_image scaled = {0};
        const obs_image *img = files[k].img;
        if (!img->data)
            continue;
        if (count > 1)
            suffixed(a->out, files[k].suffix, path, sizeof path);
        else
            snprintf(path, sizeof path, "%s", a->out);
        if (img == &r->sample_count || img == &r->bent) {
            s = img == &r->bent ? png_scaled(img, 0.5f, 0.5f, &scaled)
                                : png_scaled(img, 1.0f / 32.0f, 0.0f, &scaled);
            if (s != OBS_OK) {
                snprintf(err, OBS_ERR_LEN, "out of memory for the sample-count image");
                return s;
            }
            img = &scaled;
        }
        obs_png_options po = {.bits = a->req.png_bits,
                              .transfer = files[k].kind == DATA ? OBS_PNG_TRANSFER_LINEAR
                                                                : (obs_png_transfer)a->req.png_transfer,
                              .display = files[k].kind == DISPLAY, .prov = &prov};
        s = write_png_out(a, path, img, &po, err);
        obs_image_free(&scaled);
        if (s == OBS_OK && verbosity >= OBS_LOG_INFO)
            fprintf(stderr, "obscura: wrote %s\n", path);
    }
    return s;
}

/* --backend B, else OBSCURA_BACKEND, names the CPU device. */
static int backend_is_cpu(const char *name)
{
    if (!name)
        name = getenv("OBSCURA_BACKEND");
    return name && !strcmp(name, "cpu");
}

static obs_status backend_from_args(const char *name, obs_backend *b)
{
    if (!name)
        name = getenv("OBSCURA_BACKEND");
    if (!name || !*name) {
        *b = OBS_BACKEND_AUTO;
        return OBS_OK;
    }
    if (obs_backend_parse(name, b) != OBS_OK)
        die_usage("backend '%s' is not one of auto|cpu|egl-device|egl-surfaceless|osmesa", name);
    return OBS_OK;
}

/* The program cache's folder of --cache-dir (NULL: not given); when
 * none can be found, says so once. */
static const char *cache_dir_of(const char *flag)
{
    static char buf[4096];
    static int said;
    char why[OBS_ERR_LEN];
    const char *d = obs_cache_dir_default(flag, buf, sizeof buf, why);
    if (why[0] && !said++)
        log_cb(NULL, OBS_LOG_WARN, why);
    return d;
}

/* --backend auto (or OBSCURA_BACKEND=auto): a GPU, else the faster of
 * the CPU device and llvmpipe, measured once and kept in the cache
 * folder (obs_device_choose); no backend named: the kept choice when
 * there is one, else an EGL GPU device, else the CPU device. */
static void choose_device(ao_args *a)
{
    const char *name = a->backend ? a->backend : getenv("OBSCURA_BACKEND");
    int named_auto = name && !strcmp(name, "auto");
    if (name && *name && !named_auto)
        return; /* a GL backend named: that one */
    obs_device_choice ch;
    char err[OBS_ERR_LEN] = "";
    if (obs_device_choose(cache_dir_of(a->cache_dir), &a->req.params, named_auto, &ch, err) != OBS_OK) {
        log_cb(NULL, OBS_LOG_WARN, err); /* measuring failed: a GL context, as before */
        return;
    }
    if (verbosity >= OBS_LOG_DEBUG || (named_auto && ch.measured && verbosity >= OBS_LOG_INFO))
        fprintf(stderr, "obscura: device: %s\n", ch.why);
    if (ch.cpu)
        a->cpu = 1;
    else if (ch.backend == OBS_BACKEND_EGL_DEVICE)
        a->backend = "egl-device";
}

/* -v: what the context built and what it loaded from the cache. */
static void log_programs(const obs_ctx *ctx)
{
    obs_ctx_info ci;
    obs_ctx_get_info(ctx, &ci);
    if (verbosity >= OBS_LOG_DEBUG)
        fprintf(stderr, "obscura: debug: programs: %lu compiled, %lu loaded, %lu rejected (cache "
                "%s%s)\n", ci.programs_compiled, ci.programs_loaded, ci.programs_rejected,
                ci.cache_dir ? ci.cache_dir : "off", ci.cache_dir && !ci.cache_writable ? ", read-only" : "");
}

/* Deep input (include/obscura/deep.h): multi-layer AO of OITAO over the compressed
 * A-buffer.  Outputs: AO.Y, the per-node AO blended by alpha; AOFront.Y,
 * the front node's AO; R,G,B,A, the front-to-back composite times AO.Y
 * (premultiplied).  PNG: NAME.ao.png, NAME.front.png, NAME.composite.png. */
/* Prints info's sanity warnings from index `from` on (escaped); with
 * --strict they fail the frame (exit 3) and `then` says what was not
 * done. */
static int cli_warnings_from(const char *in, const obs_exr_info *info, int from, int strict,
                             const char *then)
{
    char shown[2 * OBS_ERR_LEN];
    for (int i = from; i < info->warning_count; i++) {
        cli_escape(info->warnings[i], shown, sizeof shown); /* a header's bytes, not the terminal's */
        fprintf(stderr, "obscura: %s: %s: %s\n", strict ? "error" : "warning", in, shown);
    }
    int n = info->warning_count - from;
    if (strict && n > 0) {
        fprintf(stderr, "obscura: error: %s: %d sanity warning%s and --strict: %s\n", in, n,
                n == 1 ? "" : "s", then);
        return EXIT_BADINPUT;
    }
    return EXIT_OK;
}

static int cli_input_warnings(const char *in, const obs_exr_info *info, int strict)
{
    return cli_warnings_from(in, info, 0, strict, "not computed");
}

/* The check after the run (obs_result_sanity: AO near 1 everywhere):
 * printed as the input's are, with --strict an error and nothing
 * written. */
static int cli_result_warnings(const ao_args *a, const obs_image *ao, const obs_gbuffer *gb,
                               const obs_deep_image *deep, obs_exr_info *info)
{
    int from = info->warning_count;
    obs_result_sanity(ao, gb, deep, &a->req.params, info);
    return cli_warnings_from(a->in, info, from, a->req.strict, "not written");
}

/* The daemon's warnings on a remote frame (its checks of the result,
 * and of the input where this process did not make them), printed and
 * failed under --strict as an in-process run's own. */
static int cli_remote_result_warnings(const ao_args *a, obs_exr_info *info)
{
    int from = info->warning_count;
    cli_remote_take_warnings(info);
    return cli_warnings_from(a->in, info, from, a->req.strict, "not written");
}

static int cmd_ao_deep(const ao_args *a, const obs_limits *lim, const char *server, int argc, char **argv)
{
    char err[OBS_ERR_LEN] = "";
    obs_deep_image d;
    obs_deep_result r = {0};
    obs_deep_ao gl_nodes = {0}; /* output=deep on GL: the pass's per-node AO */
    obs_ctx *ctx = NULL;
    obs_status s;
    int rc = EXIT_OK;

    if (a->camera)
        die_usage("ao: deep input takes the camera from the EXR header or --fov-y");
    if (a->req.append) {
        snprintf(err, OBS_ERR_LEN, "--append: the input is a deep EXR; appending the AO to a deep file is not "
                 "supported (write the AO on its own, without --append)");
        return cli_fail(OBS_UNSUPPORTED, a->in, err);
    }
    if ((a->req.outputs & OBS_OUTPUT_DEEP) &&
        (a->req.outputs != OBS_OUTPUT_DEEP || a->req.format != OBS_HTTP_EXR || !strcmp(a->out, "-"))) {
        snprintf(err, OBS_ERR_LEN, "--output deep writes one deep EXR file: not with other outputs, PNG "
                 "or stdout");
        return cli_fail(OBS_INVALID_ARGUMENT, a->in, err);
    }
    if ((a->req.outputs & OBS_OUTPUT_DEEP) && a->req.params.receivers[0]) {
        snprintf(err, OBS_ERR_LEN, "--output deep writes every node's AO, which --receivers (a mask "
                 "of each pixel's front sample) does not reach: not together");
        return cli_fail(OBS_INVALID_ARGUMENT, a->in, err);
    }
    double t0 = now_ms();
    s = a->in_buf ? obs_deep_read_exr_mem(a->in_buf, a->in_len, lim, &d, err) : obs_deep_read_exr(a->in, lim, &d, err);
    if (s == OBS_OK) /* object masks: receivers at the front samples, the rest at every sample */
        s = obs_deep_read_masks(&d, a->in_buf ? NULL : a->in, a->in_buf, a->in_len,
                                &a->req.params, lim, err);
    if (s != OBS_OK) {
        obs_deep_free(&d);
        return cli_input_fail(s, a->in, err);
    }
    double t_read = now_ms() - t0;
    /* the camera's cross-checks (the deep reader keeps the camera only) */
    obs_exr_info dinfo = {0};
    obs_camera dcam;
    if (!a->in_buf && obs_exr_describe_camera(a->in, d.part, &dinfo, &dcam, err) == OBS_OK &&
        (rc = cli_input_warnings(a->in, &dinfo, a->req.strict)) != EXIT_OK)
        goto done;
    t0 = now_ms();
    if (server && (a->req.outputs & OBS_OUTPUT_DEEP)) {
        /* the daemon answers the deep EXR itself: written as it came */
        obs_bytes file = {0};
        if ((rc = cli_remote_run_deep_file(server, argc, argv, a->in, &d, &file)) == EXIT_OK &&
            (rc = cli_remote_result_warnings(a, &dinfo)) == EXIT_OK) {
            if ((s = put_file(a->out, &file, err)) != OBS_OK)
                rc = cli_fail(s, a->out, err);
            else if (verbosity >= OBS_LOG_INFO)
                fprintf(stderr, "obscura: wrote %s\n", a->out);
        }
        obs_bytes_free(&file);
        goto done;
    } else if (a->cpu) {
        s = obs_deep_run_cpu(&d, &a->req.params, &r, err);
    } else if (server) { /* clients/remote.c prints its own errors */
        if ((rc = cli_remote_run_deep(server, argc, argv, a->in, &d, a->req.outputs, half_answer(a), &r)) != EXIT_OK)
            goto done;
    } else {
        obs_ctx_desc desc = {.debug = a->debug_gl, .log = log_cb, .cache_dir = cache_dir_of(a->cache_dir)};
        backend_from_args(a->backend, &desc.backend);
        if ((s = obs_ctx_create(&desc, &ctx, err)) != OBS_OK) {
            rc = cli_fail(s, "OpenGL", err);
            goto done;
        }
        /* output=deep: every node's AO from the pass itself */
        s = (a->req.outputs & OBS_OUTPUT_DEEP) ? obs_deep_run_nodes(ctx, &d, &a->req.params, &r, &gl_nodes, err)
                                               : obs_deep_run(ctx, &d, &a->req.params, &r, err);
        log_programs(ctx);
    }
    if (s != OBS_OK) {
        rc = cli_fail(s, a->in, err);
        goto done;
    }
    double t_run = now_ms() - t0;
    if ((rc = cli_result_warnings(a, &r.ao_front, NULL, &d, &dinfo)) != EXIT_OK)
        goto done;
    const obs_camera *cam = d.camera.has_projection ? &d.camera : NULL;
    int want_ao = (a->req.outputs & OBS_OUTPUT_AO) != 0, want_comp = (a->req.outputs & OBS_OUTPUT_COMPOSITE) != 0;
    if (a->req.outputs & OBS_OUTPUT_DEEP) {
        /* every kept node's AO (the GL pass's; with --cpu the CPU twin's,
         * computed here), the run's flat AO and front AO beside it */
        obs_deep_ao computed = {0};
        const obs_deep_ao *nodes = &gl_nodes;
        if (!gl_nodes.offset) {
            s = obs_deep_ao_nodes(&d, &a->req.params, &computed, err);
            nodes = &computed;
        }
        if (s == OBS_OK)
            s = obs_deep_ao_write_exr(a->out, nodes, &r.ao_blend, &r.ao_front,
                                      (obs_exr_compression)a->req.compression, err);
        obs_deep_ao_free(&computed);
        if (s == OBS_OK && verbosity >= OBS_LOG_INFO)
            fprintf(stderr, "obscura: wrote %s\n", a->out);
    } else if (a->req.format == OBS_HTTP_EXR) {
        obs_exr_layer layers[3];
        int n = obs_deep_result_exr_layers(&r, a->req.outputs, layers);
        s = write_exr_out(a, layers, n, cam, d.part, err);
        if (s == OBS_OK && verbosity >= OBS_LOG_INFO)
            fprintf(stderr, "obscura: wrote %s\n", a->out);
    } else {
        const struct {
            const obs_image *img;
            const char *suffix;
            int on, srgb;
        } files[] = {{&r.ao_blend, "ao", want_ao, 0},
                     {&r.ao_front, "front", want_ao, 0},
                     {&r.composite, "composite", want_comp, 1}};
        s = one_png_for_stdout(a, 2 * want_ao + want_comp, err);
        for (size_t k = 0; k < 3 && s == OBS_OK; k++) {
            char path[4096];
            if (!files[k].on)
                continue;
            suffixed(a->out, files[k].suffix, path, sizeof path);
            obs_provenance prov = provenance_of(a);
            obs_png_options po = {.bits = a->req.png_bits, .transfer = (obs_png_transfer)a->req.png_transfer,
                                  .display = files[k].srgb, .prov = &prov};
            s = write_png_out(a, path, files[k].img, &po, err);
            if (s == OBS_OK && verbosity >= OBS_LOG_INFO)
                fprintf(stderr, "obscura: wrote %s\n", path);
        }
    }
    if (s != OBS_OK) {
        rc = cli_fail(s, a->out, err);
        goto done;
    }
    if (verbosity >= OBS_LOG_INFO) {
        obs_params p;
        obs_deep_params_resolve(&d, &a->req.params, &p);
        char kernel[96]; /* the method's samples */
        if (p.method == OBS_METHOD_GTAO)
            snprintf(kernel, sizeof kernel, "gtao %d slices x %d steps%s", p.gtao_slices,
                     p.gtao_steps, obs_deep_intervals_in_effect(&d, &p)
                                       ? ", intervals (free arcs, the exact integral)" : "");
        else if (p.method == OBS_METHOD_HBAO)
            snprintf(kernel, sizeof kernel, "hbao %d directions x %d steps", p.hbao_directions,
                     p.hbao_steps);
        else if (p.method == OBS_METHOD_HEMISPHERE)
            snprintf(kernel, sizeof kernel, "%d hemisphere samples", p.hemisphere_samples);
        else
            snprintf(kernel, sizeof kernel, "%d samples%s", p.samples,
                     obs_deep_intervals_in_effect(&d, &p) ? ", intervals" : "");
        fprintf(stderr, "obscura: info: deep %dx%d, %llu samples, %s, %d nodes%s, %s hulls, "
                "radius %g, %s: read %.1f ms, AO %.1f ms\n",
                d.width, d.height, (unsigned long long)d.offset[(size_t)d.width * d.height],
                p.deep_mode == OBS_DEEP_SINGLE ? "single-layer" : "multi-layer", p.deep_layers,
                p.deep_front_half == OBS_ON ? " (front half kept)" : "",
                p.deep_hull == OBS_DEEP_THIN ? "thin" : "solid", p.radius, kernel, t_read, t_run);
    }
done:
    obs_deep_result_free(&r);
    obs_deep_ao_free(&gl_nodes);
    obs_ctx_destroy(ctx);
    obs_deep_free(&d);
    return rc;
}

/* The input's layout and camera, at --verbose. */
static void print_input_info(const char *in, const obs_exr_info *info, const obs_gbuffer *gb)
{
    if (verbosity >= OBS_LOG_INFO) {
        fprintf(stderr, "obscura: info: %s: %dx%d, preset %s, depth %s, normals %s, colour %s\n",
                in, gb->width, gb->height, info->preset, info->depth,
                info->normal[0][0] ? info->normal[0] : "(none)",
                info->color[0][0] ? info->color[0] : "(none)");
    }
    if (verbosity >= OBS_LOG_INFO && info->camera_source[0])
        fprintf(stderr, "obscura: info: camera from %s%s%s\n", info->camera_source,
                info->camera_check[0] ? "; " : "", info->camera_check);
}

/* The camera: --camera's file, else the header's, else solved from the
 * positions (--solve-camera); then the frame's sanity checks. */
static int prepare_camera(const ao_args *a, obs_gbuffer_file *gf, char err[OBS_ERR_LEN])
{
    obs_status s;
    if (a->camera) {
        int cw = 0, ch = 0;
        s = obs_camera_read_json(a->camera, &gf->gb.camera, &cw, &ch, err);
        if (s != OBS_OK)
            return cli_input_fail(s, a->camera, err);
        int dw = gf->gb.display_width > 0 ? gf->gb.display_width : gf->gb.width;
        int dh = gf->gb.display_height > 0 ? gf->gb.display_height : gf->gb.height;
        if (cw > 0 && ch > 0 && fabs((double)cw / ch - (double)dw / dh) > 1e-3)
            fprintf(stderr, "obscura: warning: camera %s is %dx%d but the image is %dx%d (aspect differs)\n",
                    a->camera, cw, ch, dw, dh);
    }
    const int had_camera = gf->gb.camera.has_projection;
    if (a->req.solve_camera && gf->gb.position.data &&
        (s = obs_gbuffer_solve_camera(gf, &a->req.params, err)) != OBS_OK)
        return cli_input_fail(s, a->in, err);
    if (!had_camera && gf->gb.camera.has_projection && verbosity >= OBS_LOG_INFO)
        fprintf(stderr, "obscura: info: camera %s, %s\n", gf->info.camera_source,
                gf->info.camera_check);
    obs_gbuffer_sanity(&gf->gb, &a->req.params, &gf->info);
    return cli_input_warnings(a->in, &gf->info, a->req.strict);
}

/* The baked channel: --baked CH, else _AO when the input has it (*bch
 * "none" when there is none to combine). */
static int read_baked(const ao_args *a, const obs_limits *lim, const obs_gbuffer *gb,
                      obs_image *baked, const char **bch, char err[OBS_ERR_LEN])
{
    *bch = a->req.baked ? a->req.baked : "_AO";
    if (strcmp(*bch, "none") == 0)
        return EXIT_OK;
    obs_status s = a->in_buf ? obs_exr_read_channel_mem(a->in_buf, a->in_len, *bch, lim, baked, err)
                             : obs_exr_read_channel(a->in, *bch, lim, baked, err);
    if (s == OBS_OK && (baked->width != gb->width || baked->height != gb->height)) {
        snprintf(err, OBS_ERR_LEN, "baked channel %s is %dx%d, the G-buffer %dx%d", *bch,
                 baked->width, baked->height, gb->width, gb->height);
        obs_image_free(baked);
        s = OBS_INVALID_ARGUMENT;
    }
    if (s != OBS_OK && a->req.baked)
        return cli_input_fail(s, a->in, err);
    if (s != OBS_OK && s != OBS_MISSING_CHANNEL) /* auto: said, and left out */
        fprintf(stderr, "obscura: warning: %s: %s; the AO is not combined with it (--baked "
                        "none: not looked for)\n", a->in, err);
    if (s != OBS_OK)
        *bch = "none"; /* auto: not a baked level's G-buffer */
    err[0] = '\0';
    return EXIT_OK;
}

/* The CPU device's memory budget for the chain's planes: --max-memory
 * (else OBSCURA_MAX_MEMORY; main took it: cli_take_max_memory; over it
 * the frame runs in bands of rows), and OBSCURA_BAND_ROWS (bands of that
 * many rows whatever the size: tests, benchmarks), which is left out,
 * said, when it is not a positive count.  Said with -v once a process. */
static void cpu_bands_opts(obs_cpu_options *o)
{
    static int said;
    cli_max_memory(o);
    if (!said++ && verbosity >= OBS_LOG_DEBUG)
        fprintf(stderr, "obscura: debug: memory budget: %s\n", cli_max_memory_text());
    const char *v = getenv("OBSCURA_BAND_ROWS");
    if (!v || !*v)
        return;
    char *end;
    long n = strtol(v, &end, 10);
    if (*end || n <= 0 || n > 1L << 20)
        fprintf(stderr, "obscura: warning: OBSCURA_BAND_ROWS=%s is not a positive count; left out\n", v);
    else
        o->band_rows = (int)n;
}

/* The chain on the CPU twin, on obscurad (--server) or on a GL context
 * (kept across a batch's frames); *t0 restarts once the context exists. */
static int run_frame(const ao_args *a, obs_gbuffer_file *gf, unsigned outputs, const char *server,
                     int combined, int argc, char **argv, obs_result *res, obs_ctx **ctx, double *t0,
                     char err[OBS_ERR_LEN])
{
    obs_status s;
    if (a->cpu) {
        obs_cpu_options o = {.log = log_cb};
        cpu_bands_opts(&o);
        s = obs_run_cpu_opts(&gf->gb, &a->req.params, outputs, res, &o, err);
    } else if (server) { /* clients/remote.c prints its own errors */
        return cli_remote_run(server, argc, argv, a->in, &gf->gb, outputs, half_answer(a) && !combined, res);
    } else {
        obs_ctx_desc desc = {.debug = a->debug_gl, .log = log_cb, .cache_dir = cache_dir_of(a->cache_dir)};
        backend_from_args(a->backend, &desc.backend);
        s = kept_ctx ? (*ctx = kept_ctx, OBS_OK) : obs_ctx_create(&desc, ctx, err);
        if (s != OBS_OK)
            return cli_fail(s, "OpenGL", err);
        if (verbosity >= OBS_LOG_DEBUG)
            fprintf(stderr, "obscura: debug: context created in %.1f ms\n", now_ms() - *t0);
        *t0 = now_ms();
        s = obs_run(*ctx, &gf->gb, &a->req.params, outputs, res, err);
        log_programs(*ctx);
    }
    if (verbosity >= OBS_LOG_DEBUG) /* tests/e2e/threads.sh reads it */
        fprintf(stderr, "obscura: debug: threads: %d in this process after the frame\n",
                cli_process_threads());
    return s == OBS_OK ? EXIT_OK : cli_fail(s, a->in, err);
}

/* The chain's AO with the baked channel's (parameter baked_combine). */
static int combine_baked(const ao_args *a, obs_result *res, const obs_image *baked,
                         const char *bch, char err[OBS_ERR_LEN])
{
    obs_status s = obs_result_combine_baked(res, baked, &a->req.params, err);
    if (s != OBS_OK)
        return cli_fail(s, a->in, err);
    if (verbosity >= OBS_LOG_INFO) {
        obs_params bp;
        obs_params_resolve(&a->req.params, &bp);
        fprintf(stderr, "obscura: info: baked channel %s combined (%s): AO.Y, AOScreen.Y, "
                        "AOBaked.Y\n", bch, bp.baked_combine == OBS_BAKED_MIN ? "min" : "product");
    }
    return EXIT_OK;
}

/* The method and its sample counts, for the --verbose line. */
static void method_text(const obs_params *p, char how[64])
{
    if (p->method == OBS_METHOD_HEMISPHERE)
        snprintf(how, 64, "hemisphere, %d samples", p->hemisphere_samples);
    else if (p->method == OBS_METHOD_ANGLE)
        snprintf(how, 64, "angle, %d pairs", p->angle_pairs);
    else if (p->method == OBS_METHOD_HBAO)
        snprintf(how, 64, "hbao, %d directions x %d steps", p->hbao_directions, p->hbao_steps);
    else if (p->method == OBS_METHOD_GTAO)
        snprintf(how, 64, "gtao, %d slices x %d steps", p->gtao_slices, p->gtao_steps);
    else
        snprintf(how, 64, "%s, %d samples", p->method == OBS_METHOD_VAO ? "vao" : "vaopp", p->samples);
}

/* The frame's size, method, device and times, at --verbose. */
static void print_run_info(const ao_args *a, const obs_gbuffer *gb, obs_ctx *ctx, double t_read,
                           double t_run, double t_write)
{
    if (verbosity < OBS_LOG_INFO)
        return;
    obs_params p;
    obs_ctx_info ci = {0};
    obs_params_resolve(&a->req.params, &p);
    if (ctx)
        obs_ctx_get_info(ctx, &ci);
    char how[64];
    method_text(&p, how);
    fprintf(stderr, "obscura: info: %dx%d, radius %g, %s, %s: read %.1f ms, AO %.1f ms, write %.1f ms\n",
            gb->width, gb->height, p.radius, how, a->cpu ? "cpu" : obs_backend_name(ci.backend),
            t_read, t_run, t_write);
}

/* A flat frame read: its camera, the baked channel, the chain, the
 * combination, the outputs. */
static int ao_flat(ao_args *a, const obs_limits *lim, const char *server, int argc, char **argv)
{
    char err[OBS_ERR_LEN] = "";
    obs_gbuffer_file gf = {0};
    obs_result res = {0};
    obs_image baked = {0};
    obs_ctx *ctx = NULL;
    const char *bch;
    double t0 = now_ms();
    obs_status s = a->in_buf ? obs_gbuffer_read_exr_mem(a->in_buf, a->in_len, &a->req.map, lim, &gf, err)
                             : obs_gbuffer_read_exr(a->in, &a->req.map, lim, &gf, err);
    /* object masks (receivers, occluders, self_only); a daemon reads its own */
    if (s == OBS_OK && !server)
        s = obs_gbuffer_read_masks(&gf, a->in_buf ? NULL : a->in, a->in_buf, a->in_len,
                                   &a->req.params, lim, err);
    if (s != OBS_OK) {
        obs_gbuffer_free(&gf);
        return cli_input_fail(s, a->in, err);
    }
    double t_read = now_ms() - t0;
    print_input_info(a->in, &gf.info, &gf.gb);
    int rc = prepare_camera(a, &gf, err);
    if (rc == EXIT_OK)
        rc = read_baked(a, lim, &gf.gb, &baked, &bch, err);
    if (rc != EXIT_OK)
        goto done;
    unsigned outputs = a->req.outputs;
    if (baked.data)
        outputs |= OBS_OUTPUT_AO; /* the combination needs the chain's AO */
    t0 = now_ms();
    if ((rc = run_frame(a, &gf, outputs, server, baked.data != NULL, argc, argv, &res, &ctx, &t0, err)) != EXIT_OK)
        goto done;
    if ((rc = server ? cli_remote_result_warnings(a, &gf.info)
                     : cli_result_warnings(a, &res.ao, &gf.gb, NULL, &gf.info)) != EXIT_OK)
        goto done;
    if (baked.data && (rc = combine_baked(a, &res, &baked, bch, err)) != EXIT_OK)
        goto done;
    double t_run = now_ms() - t0;
    t0 = now_ms();
    obs_camera cam; /* the parameters' over the input's, as obscurad writes it */
    s = write_outputs(a, &res, obs_camera_of_run(&gf.gb, &a->req.params, &cam) ? &cam : NULL, gf.info.part, err);
    if (s != OBS_OK) {
        rc = cli_fail(s, a->out, err);
        goto done;
    }
    print_run_info(a, &gf.gb, ctx, t_read, t_run, now_ms() - t0);
done:
    obs_image_free(&baked);
    obs_result_free(&res);
    if (keep_ctx)
        kept_ctx = ctx;
    else
        obs_ctx_destroy(ctx);
    obs_gbuffer_free(&gf);
    return rc;
}

/* ---- a frame by rows: neither the G-buffer nor the result whole in memory ----
 *
 * On the CPU device, a flat EXR input whose working set (the input's
 * planes, the chain's, the result's) is over the memory budget
 * (OBSCURA_MAX_MEMORY MiB, else a quarter of the usable memory; or
 * any size with OBSCURA_BAND_ROWS) is read by rows (the chain's planes
 * get the budget's share they have in the whole frame's working set), run in bands and
 * written by rows (obs_run_cpu_rows, obs_gbuffer_rows_*, obs_exr_rows_*):
 * the same file as the whole frame's.  Only a plain EXR output of a file
 * input, with the camera at hand and no object masks, baked channel,
 * --layer or --append; otherwise the frame is read whole. */

typedef struct ao_rows_job {
    const ao_args *a;
    obs_gbuffer_rows *rows;
    obs_exr_rows *w;
    obs_exr_options o;
    int height;
    double t_in, t_out; /* ms reading and writing */
} ao_rows_job;

static obs_status ao_rows_in(void *user, int y0, int y1, obs_gbuffer *rows, char err[OBS_ERR_LEN])
{
    ao_rows_job *j = user;
    double t0 = now_ms();
    obs_status s = obs_gbuffer_rows_read(j->rows, y0, y1, rows, err);
    j->t_in += now_ms() - t0;
    return s;
}

static obs_status ao_rows_out(void *user, int y0, int y1, const obs_result *res, char err[OBS_ERR_LEN])
{
    ao_rows_job *j = user;
    obs_exr_layer layers[OBS_RESULT_LAYERS];
    int n = obs_result_exr_layers(res, layers);
    double t0 = now_ms();
    (void)y0, (void)y1; /* in order: the writer counts them */
    obs_status s = j->w ? OBS_OK : obs_exr_rows_open(j->a->out, layers, n, j->height, &j->o, &j->w, err);
    if (s == OBS_OK)
        s = obs_exr_rows_write(j->w, layers, n, err);
    j->t_out += now_ms() - t0;
    return s;
}

/* The bytes a pixel of the frame takes read whole: its planes, the CPU
 * chain's (about 56 at the default parameters) and the result's. */
static double whole_bytes_per_px(const obs_gbuffer *gb, unsigned outputs)
{
    double in = 4.0 * (1 + gb->normal.channels + gb->color.channels);
    double out = 4.0 * (!!(outputs & OBS_OUTPUT_AO) + 4 * !!(outputs & OBS_OUTPUT_COMPOSITE) +
                        3 * !!(outputs & OBS_OUTPUT_BENT) + 3 * !!(outputs & OBS_OUTPUT_BLEED) + 3);
    return in + 56.0 + out;
}

/* --max-memory's budget (or OBSCURA_MAX_MEMORY's), else the library's
 * default. */
static double memory_budget(void)
{
    obs_cpu_options o = {0};
    cli_max_memory(&o);
    return (double)obs_cpu_memory_budget(&o);
}

/* -1: the frame is to be read whole (ao_flat); else the exit code. */
static int ao_rows(ao_args *a, const obs_limits *lim)
{
    const obs_params *p = &a->req.params;
    const char *forced = getenv("OBSCURA_BAND_ROWS");
    if (!a->cpu || a->in_buf || a->to_stdout || a->req.format != OBS_HTTP_EXR || a->req.append ||
        a->req.layer || p->receivers[0] || p->occluders[0] || p->self_only == OBS_ON)
        return -1;
    char err[OBS_ERR_LEN] = "";
    obs_gbuffer_file meta;
    ao_rows_job j = {.a = a};
    if (obs_gbuffer_rows_open(a->in, &a->req.map, lim, &j.rows, &meta, err) != OBS_OK)
        return -1; /* the whole reader says why, or reads what this one does not */
    double need = whole_bytes_per_px(&meta.gb, a->req.outputs) * meta.gb.width * meta.gb.height;
    int whole = !(forced && *forced) && need <= memory_budget();
    /* a baked channel to combine (--baked, or the input's _AO) needs the
     * frame whole (obs_result_combine_baked) */
    char **names = NULL;
    const char *bch = a->req.baked ? a->req.baked : "_AO";
    if (!whole && strcmp(bch, "none") != 0 && obs_exr_list_channels(a->in, &names, err) == OBS_OK)
        for (char **nm = names; *nm && !whole; nm++)
            whole = !strcmp(*nm, bch);
    obs_strv_free(names);
    if (!whole && a->camera) {
        obs_status s = obs_camera_read_json(a->camera, &meta.gb.camera, NULL, NULL, err);
        if (s != OBS_OK) {
            obs_gbuffer_rows_close(j.rows);
            return cli_input_fail(s, a->camera, err);
        }
    }
    obs_camera cam;
    if (!whole && !obs_camera_of_run(&meta.gb, p, &cam))
        whole = 1; /* no camera: the whole reader solves it from the positions, or says so */
    if (whole) {
        obs_gbuffer_rows_close(j.rows);
        return -1;
    }
    print_input_info(a->in, &meta.info, &meta.gb);
    /* the colour only where the chain reads it: the rows half the size
     * with RGBA otherwise */
    obs_params rp;
    obs_params_resolve(p, &rp);
    if (!(a->req.outputs & (OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_MULTIBOUNCE | OBS_OUTPUT_LUMINANCE |
                            OBS_OUTPUT_BLEED)) &&
        rp.luminance == OBS_LUMINANCE_OFF && rp.bleeding == OBS_BLEEDING_OFF && rp.multibounce != OBS_ON) {
        obs_gbuffer_rows_no_color(j.rows);
        meta.gb.color = (obs_plane){NULL, 0, 0};
    }
    if (verbosity >= OBS_LOG_INFO)
        fprintf(stderr, "obscura: info: %dx%d needs about %.0f MiB read whole, %s %s: read, run and "
                        "written by rows (the input's sanity checks, which read the whole frame, are left "
                        "out)\n", meta.gb.width, meta.gb.height, need / 1048576.0,
                forced && *forced ? "bands asked by" : "over the memory budget of",
                forced && *forced ? "OBSCURA_BAND_ROWS" : cli_max_memory_text());
    obs_exr_source src = {.path = a->in, .part = meta.info.part};
    obs_provenance prov = provenance_of(a);
    j.o = (obs_exr_options){.pixel = a->req.float_exr ? OBS_EXR_FLOAT : OBS_EXR_HALF, .cam = &cam, .src = &src,
                            .prov = &prov, .compression = (obs_exr_compression)a->req.compression};
    j.height = meta.gb.height;
    obs_cpu_options o = {.log = log_cb};
    cpu_bands_opts(&o);
    /* the budget is the frame's: the chain's planes get their share of it
     * (the rows of the input and of the result the rest) */
    o.max_memory = (size_t)(memory_budget() * 56.0 / whole_bytes_per_px(&meta.gb, a->req.outputs));
    double t0 = now_ms();
    obs_status s = obs_run_cpu_rows(&meta.gb, ao_rows_in, ao_rows_out, &j, p, a->req.outputs, &o, err);
    double t_all = now_ms() - t0;
    char werr[OBS_ERR_LEN] = "";
    obs_status ws = j.w ? obs_exr_rows_close(j.w, s, werr) : s;
    obs_gbuffer_rows_close(j.rows);
    if (s != OBS_OK)
        return cli_fail(s, a->in, err);
    if (ws != OBS_OK)
        return cli_fail(ws, a->out, werr);
    if (verbosity >= OBS_LOG_INFO) {
        fprintf(stderr, "obscura: wrote %s\n", a->out);
        print_run_info(a, &meta.gb, NULL, j.t_in, t_all - j.t_in - j.t_out, j.t_out);
    }
    return EXIT_OK;
}

/* IN '-': stdin's whole EXR in memory (the readers take it from there,
 * as the daemon's do a request body); 4 GiB at most. */
static int read_stdin(ao_args *a)
{
    size_t cap = 1 << 20;
    unsigned char *b = malloc(cap);
    size_t n = 0, got;
    while (b && (got = fread(b + n, 1, cap - n, stdin)) > 0) {
        n += got;
        if (n < cap)
            continue;
        unsigned char *nb = cap < ((size_t)1 << 32) ? realloc(b, cap * 2) : NULL;
        if (!nb)
            free(b);
        b = nb;
        cap *= 2;
    }
    if (!b || ferror(stdin)) {
        obs_status s = b ? OBS_IO : OBS_TOO_LARGE;
        free(b);
        return cli_input_fail(s, "-", s == OBS_IO ? "cannot read stdin" : "stdin: too large (4 GiB at most) or out of memory");
    }
    a->in_buf = b;
    a->in_len = n;
    return EXIT_OK;
}

static int cmd_ao(int argc, char **argv)
{
    ao_args a;
    char err[OBS_ERR_LEN] = "";
    const char *server = NULL;
    argc = cli_remote_take_server(argc, argv, &server);
    parse_ao(argc, argv, &a);
    if (!server && backend_is_cpu(a.backend)) /* with --server the backend is obscurad's */
        a.cpu = 1;
    if (!server && !a.cpu)
        choose_device(&a);
    static int said_budget; /* once a batch */
    if ((server || !a.cpu) && cli_max_memory_given() && !said_budget++ && verbosity >= OBS_LOG_INFO)
        fprintf(stderr, "obscura: info: --max-memory is the CPU device's budget: %s\n",
                server ? "the frame runs on obscurad, whose own --max-memory applies"
                       : "the frame runs on a GL context, whole");
    obs_limits lim = {0};
    if (a.max_size)
        lim.max_width = lim.max_height = (int)a.max_size;
    int deep = 0, rc;
    if (!strcmp(a.in, "-")) {
        if (server)
            die_usage("ao: IN '-' (stdin) runs in-process: with --server give the file's path");
        if ((rc = read_stdin(&a)) != EXIT_OK)
            return rc;
    }
    obs_status s = a.in_buf ? obs_exr_is_deep_mem(a.in_buf, a.in_len, &deep, err) : obs_exr_is_deep(a.in, &deep, err);
    if (s == OBS_OK && deep) {
        if (a.req.baked && strcmp(a.req.baked, "none") != 0)
            die_usage("ao: --baked: the input is a deep EXR; a baked channel is combined with "
                      "flat input only");
        if (a.cpu && getenv("OBSCURA_BAND_ROWS") && verbosity >= OBS_LOG_INFO)
            fprintf(stderr, "obscura: info: deep input is read and run whole (bands of rows are for "
                            "flat frames: a deep pixel's node lists have no fixed size a row)\n");
        rc = cmd_ao_deep(&a, &lim, server, argc, argv);
    } else if (s == OBS_OK && (a.req.outputs & OBS_OUTPUT_DEEP)) {
        rc = cli_fail(OBS_INVALID_ARGUMENT, a.in,
                      "--output deep: the input is not a deep EXR (the deep AO is of deep input's nodes)");
    } else if (server || (rc = ao_rows(&a, &lim)) < 0) {
        rc = ao_flat(&a, &lim, server, argc, argv);
    }
    free(a.in_buf);
    return rc;
}

/* The hooks of obscura batch (clients/batch.c). */
static void batch_check(int argc, char **argv)
{
    ao_args a;
    const char *server;
    argc = cli_remote_take_server(argc, argv, &server);
    parse_ao(argc, argv, &a);
}

static int batch_ao(int argc, char **argv)
{
    keep_ctx = 1;
    return cmd_ao(argc, argv);
}

static void batch_finish(void)
{
    obs_ctx_destroy(kept_ctx);
    kept_ctx = NULL;
}

/* info's thread lines: the limit, llvmpipe's count and where it came
 * from, and the threads running now that the context exists; then the
 * CPU device's memory budget and where it came from. */
static void print_threads(int llvmpipe)
{
    obs_threads_info ti;
    obs_threads_get(&ti);
    if (ti.limit)
        printf("threads: %d (--threads or OBSCURA_THREADS)\n", ti.limit);
    else
        printf("threads: every core (%d; --threads N or OBSCURA_THREADS bounds them)\n", ti.pool);
    if (!llvmpipe)
        printf("llvmpipe threads: not in use\n");
    else if (ti.llvmpipe < 0)
        printf("llvmpipe threads: one per core (LP_NUM_THREADS unset)\n");
    else
        printf("llvmpipe threads: %d (LP_NUM_THREADS %s)\n", ti.llvmpipe,
               ti.llvmpipe_from_user ? "from the environment, kept" : "set from --threads");
    printf("process threads: %d\n", cli_process_threads());
    printf("memory budget (CPU device): %s\n", cli_max_memory_text());
}

static int cmd_info(int argc, char **argv)
{
    const char *backend = NULL, *cache = NULL, *v;
    for (int i = 0; i < argc; i++) {
        if ((v = opt_value(argc, argv, &i, "backend")))
            backend = v;
        else if ((v = opt_value(argc, argv, &i, "cache-dir")))
            cache = v;
        else
            die_usage("info: unknown argument '%s'", argv[i]);
    }
    if (backend_is_cpu(backend)) {
        printf("obscura %s\nbackend: cpu (the chain on the CPU device, no GL context)\n",
               OBS_VERSION);
        print_threads(0);
        return EXIT_OK;
    }
    obs_ctx_desc desc = {.log = log_cb, .cache_dir = cache_dir_of(cache)};
    char err[OBS_ERR_LEN] = "";
    obs_ctx *ctx;
    backend_from_args(backend, &desc.backend);
    verbosity = OBS_LOG_WARN;
    obs_status s = obs_ctx_create(&desc, &ctx, err);
    if (s != OBS_OK)
        return cli_fail(s, "OpenGL", err);
    obs_ctx_info info;
    obs_ctx_get_info(ctx, &info);
    printf("obscura %s\nbackend: %s\nGL version: %s\nGL vendor: %s\nGL renderer: %s\n", OBS_VERSION,
           obs_backend_name(info.backend), info.gl_version, info.gl_vendor, info.gl_renderer);
    printf("program cache: %s%s\n", info.cache_dir ? info.cache_dir : "off",
           !info.cache_dir ? "" : info.cache_writable ? "" : " (read-only)");
    print_threads(strstr(info.gl_renderer, "llvmpipe") != NULL);
    obs_ctx_destroy(ctx);
    return EXIT_OK;
}

static int cmd_params(int argc, char **argv)
{
    int markdown = argc > 0 && !strcmp(argv[0], "--markdown");
    if (markdown)
        printf("| parameter | type | default | range | meaning |\n|---|---|---|---|---|\n");
    for (int i = 0; i < obs_param_count(); i++) {
        const obs_param_info *pi = obs_param_at(i);
        static const char *const types[] = {"float", "int", "enum", "16 floats", "text"};
        char range[96];
        param_range(pi, 1, range, sizeof range);
        if (markdown) /* '|' would end a Markdown table cell */
            for (char *c = range; *c; c++)
                if (*c == '|')
                    *c = '/';
        char flag[48];
        param_flag(pi, flag, sizeof flag);
        if (markdown) {
            printf("| `%s` | %s | %s | %s | ", flag, types[pi->type], pi->def, range);
            for (const char *c = pi->doc; *c; c++) { /* a bare '|' would end the cell */
                if (*c == '|')
                    putchar('\\');
                putchar(*c);
            }
            printf(" |\n");
        } else
            printf("%-18s %-9s default %-8s %-20s %s\n", flag, types[pi->type], pi->def, range, pi->doc);
    }
    return EXIT_OK;
}

/* Runs the sample generator (VAO++ section 4.5) and prints its sets; with
 * --c as the C source of core/chain/sample_tables.c (make samples). */
static int cmd_samples(int argc, char **argv)
{
    static const int sizes[] = {2, 4, 8, 16, 32};
    int c_source = 0;
    for (int i = 0; i < argc; i++) {
        if (cli_is_switch(argv[i], "c"))
            c_source = 1;
        else
            die_usage("samples: unknown argument '%s'", argv[i]);
    }
    if (c_source)
        printf("/* The sample sets of VAO++ section 4.5: generated by `obscura samples --c`\n"
               " * (make samples) from core/chain/samples_gen.c; do not edit.\n"
               " * tests/unit/core/test_samples.c regenerates them and compares. */\n"
               "#include \"internal.h\"\n\n"
               "const float obs__sample_table[OBS_SAMPLE_TABLE_LEN][2] = {\n");
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        int n = sizes[k];
        float xy[64];
        obs_status s = obs_samples_generate(n, xy);
        if (s != OBS_OK)
            return cli_fail(s, "samples", NULL);
        if (c_source)
            printf("    /* %d samples, from pair %d */\n", n, n - 2);
        else
            printf("%d samples:\n", n);
        for (int i = 0; i < n; i++) {
            if (c_source) /* %.9e: every float reads back exactly */
                printf("    {%.9ef, %.9ef},\n", (double)xy[2 * i], (double)xy[2 * i + 1]);
            else
                printf("  %2d  % .6f  % .6f\n", i, (double)xy[2 * i], (double)xy[2 * i + 1]);
        }
    }
    if (c_source)
        printf("};\n");
    return EXIT_OK;
}

/* The depth channel of a G-buffer EXR, for the geometry mask. */
static int load_mask(const char *path, const char *channel, const obs_image *like,
                     unsigned char **mask, char err[OBS_ERR_LEN])
{
    obs_image d = {0};
    obs_status s;
    if (channel) {
        s = obs_exr_read_channel(path, channel, NULL, &d, err);
    } else {
        obs_gbuffer_file gf = {0};
        s = obs_gbuffer_read_exr(path, NULL, NULL, &gf, err);
        if (s == OBS_OK) {
            s = obs_exr_read_channel(path, gf.info.depth, NULL, &d, err);
            obs_gbuffer_free(&gf);
        }
    }
    if (s != OBS_OK)
        return -1;
    if (d.width != like->width || d.height != like->height) {
        snprintf(err, OBS_ERR_LEN, "mask %dx%d does not match the image %dx%d", d.width, d.height,
                 like->width, like->height);
        obs_image_free(&d);
        return -1;
    }
    size_t n = (size_t)d.width * d.height;
    *mask = malloc(n);
    if (!*mask) {
        obs_image_free(&d);
        snprintf(err, OBS_ERR_LEN, "out of memory");
        return -1;
    }
    for (size_t i = 0; i < n; i++)
        (*mask)[i] = isfinite(d.data[i]) && d.data[i] > 0.0f && d.data[i] < 1e9f;
    obs_image_free(&d);
    return 0;
}

/* First channel of the list that the file has. */
static const char *pick_channel(const char *path, const char *const *cands, char *buf, size_t len,
                                char err[OBS_ERR_LEN])
{
    char **names = NULL;
    if (obs_exr_list_channels(path, &names, err) != OBS_OK)
        return NULL;
    const char *found = NULL;
    for (int c = 0; cands[c] && !found; c++)
        for (char **n = names; *n && !found; n++)
            if (!strcmp(*n, cands[c])) {
                snprintf(buf, len, "%s", *n);
                found = buf;
            }
    if (!found)
        snprintf(err, OBS_ERR_LEN, "none of the usual AO channels (AO.Y, Y, ViewLayer.AO.R, A, R) is in %s; use --channel-a/--channel-b", path);
    obs_strv_free(names);
    return found;
}

/* The --json line of compare: one object on one line, "key": value, built
 * with cJSON (names are escaped; NaN becomes null). */
static void print_compare_json(const char *pa, const char *cha, const char *pb, const char *chb,
                               const char *mask, const obs_metrics *m)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "truth", pa);
    cJSON_AddStringToObject(o, "channel_a", cha);
    cJSON_AddStringToObject(o, "candidate", pb);
    cJSON_AddStringToObject(o, "channel_b", chb);
    cJSON_AddStringToObject(o, "mask", mask);
    cJSON_AddNumberToObject(o, "mse", m->mse);
    cJSON_AddNumberToObject(o, "mae", m->mae);
    cJSON_AddNumberToObject(o, "psnr", m->psnr);
    cJSON_AddNumberToObject(o, "ssim", m->ssim);
    cJSON_AddNumberToObject(o, "corr", m->corr);
    cJSON_AddNumberToObject(o, "bias", m->bias);
    cJSON_AddNumberToObject(o, "pixels", (double)m->count);
    const cJSON *c;
    const char *sep = "{";
    cJSON_ArrayForEach(c, o) {
        cJSON *key = cJSON_CreateString(c->string);
        char *v = cJSON_PrintUnformatted(c), *k = key ? cJSON_PrintUnformatted(key) : NULL;
        printf("%s%s: %s", sep, k ? k : "\"\"", v ? v : "null");
        cJSON_free(v);
        cJSON_free(k);
        cJSON_Delete(key);
        sep = ", ";
    }
    printf("}\n");
    cJSON_Delete(o);
}

/* compare --diff: PNG, the RGB map of obs_metrics_diff_image(); EXR, the
 * same map as R,G,B plus the signed difference (candidate - truth, of the
 * clamped values) as Diff.Y. */
static obs_status write_diff(const char *path, const obs_image *a, const obs_image *b,
                             const obs_image *map, char err[OBS_ERR_LEN])
{
    size_t n = strlen(path);
    if (n < 4 || strcasecmp(path + n - 4, ".exr") != 0)
        return obs_png_write(path, map, 8, 0, err);
    size_t px = (size_t)a->width * a->height;
    obs_image d = {a->width, a->height, 1, malloc(px * sizeof(float))};
    if (!d.data) {
        snprintf(err, OBS_ERR_LEN, "out of memory for the difference image");
        return OBS_NO_MEMORY;
    }
    for (size_t i = 0; i < px; i++)
        d.data[i] = fminf(fmaxf(b->data[i], 0.0f), 1.0f) - fminf(fmaxf(a->data[i], 0.0f), 1.0f);
    static const char *const rgb[] = {"R", "G", "B"}, *const dy[] = {"Diff.Y"};
    const obs_exr_layer layers[] = {{map, rgb}, {&d, dy}};
    obs_status s = obs_exr_write(path, layers, 2, OBS_EXR_FLOAT, NULL, err);
    obs_image_free(&d);
    return s;
}

static int cmd_compare(int argc, char **argv)
{
    static const char *const ao_cands[] = {"AO.Y", "Y", "ViewLayer.AO.R", "A", "R", NULL};
    const char *pa = NULL, *pb = NULL, *cha = NULL, *chb = NULL, *mask_opt = "auto", *diff = NULL;
    int json = 0;
    for (int i = 0; i < argc; i++) {
        const char *v;
        if ((v = opt_value(argc, argv, &i, "channel-a")))
            cha = v;
        else if ((v = opt_value(argc, argv, &i, "channel-b")))
            chb = v;
        else if ((v = opt_value(argc, argv, &i, "mask")))
            mask_opt = v;
        else if ((v = opt_value(argc, argv, &i, "diff")))
            diff = v;
        else if (cli_is_switch(argv[i], "json"))
            json = 1;
        else if (argv[i][0] == '-')
            die_usage("compare: unknown option '%s'", argv[i]);
        else if (!pa)
            pa = argv[i];
        else if (!pb)
            pb = argv[i];
        else
            die_usage("compare: more than two files");
    }
    if (!pa || !pb)
        die_usage("compare: needs two files, TRUTH and CANDIDATE");

    char err[OBS_ERR_LEN] = "", bufa[128], bufb[128];
    obs_image a = {0}, b = {0};
    unsigned char *mask = NULL;
    obs_status s;
    int rc = EXIT_OK;
    if (!cha && !(cha = pick_channel(pa, ao_cands, bufa, sizeof bufa, err)))
        return cli_fail(OBS_MISSING_CHANNEL, pa, err);
    if (!chb && !(chb = pick_channel(pb, ao_cands, bufb, sizeof bufb, err)))
        return cli_fail(OBS_MISSING_CHANNEL, pb, err);
    if ((s = obs_exr_read_channel(pa, cha, NULL, &a, err)) != OBS_OK)
        return cli_fail(s, pa, err);
    if ((s = obs_exr_read_channel(pb, chb, NULL, &b, err)) != OBS_OK) {
        rc = cli_fail(s, pb, err);
        goto done;
    }
    if (strcmp(mask_opt, "none") != 0) {
        /* auto: the depth channel of TRUTH (else CANDIDATE) selects geometry */
        const char *mch = strcmp(mask_opt, "auto") ? mask_opt : NULL;
        if (load_mask(pa, mch, &a, &mask, err) != 0) {
            char err2[OBS_ERR_LEN];
            if (mch || load_mask(pb, NULL, &a, &mask, err2) != 0) {
                if (mch) {
                    rc = cli_fail(OBS_MISSING_CHANNEL, "--mask", err);
                    goto done;
                }
                mask = NULL; /* no depth anywhere: compare every pixel */
            }
        }
    }
    obs_metrics m;
    s = obs_metrics_compute(&a, &b, mask, &m, err);
    if (s != OBS_OK) {
        rc = cli_fail(s, "compare", err);
        goto done;
    }
    if (json)
        print_compare_json(pa, cha, pb, chb, mask ? mask_opt : "none", &m);
    else
        printf("%s (%s) vs %s (%s), %lld pixels%s\n  MSE %.6f  PSNR %.2f dB  SSIM %.4f  MAE %.5f  "
               "corr %.4f  bias %+.5f\n",
               pa, cha, pb, chb, m.count, mask ? " with geometry" : "", m.mse, m.psnr, m.ssim, m.mae,
               m.corr, m.bias);
    if (diff) {
        obs_image d = {0};
        s = obs_metrics_diff_image(&a, &b, &d, err);
        if (s == OBS_OK)
            s = write_diff(diff, &a, &b, &d, err);
        obs_image_free(&d);
        if (s != OBS_OK)
            rc = cli_fail(s, diff, err);
    }
done:
    free(mask);
    obs_image_free(&a);
    obs_image_free(&b);
    return rc;
}

static int cmd_batch(int argc, char **argv)
{
    static const cli_batch_ops ops = {batch_check, batch_ao, batch_finish};
    return cli_batch(argc, argv, &ops);
}

/* The commands: a new one is a row (and its usage lines). */
static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
    int threads; /* takes --threads (cli_take_threads): it renders, bakes or reads images */
    int memory;  /* takes --max-memory (cli_take_max_memory): its frames may run on the CPU device */
} commands[] = {
    {"ao", cmd_ao, 1, 1},
    {"inspect", cli_inspect, 1, 0},
    {"compare", cmd_compare, 1, 0},
    {"info", cmd_info, 1, 1}, /* says the budget */
    {"params", cmd_params, 0, 0},
    {"samples", cmd_samples, 0, 0},
    {"gbuffer", cli_gbuffer, 1, 0},
    {"reference", cli_reference, 1, 0},
    {"warmup", cli_warmup, 1, 0},
    {"bake", cli_bake, 1, 0},
    {"bake-dynamic", cli_dynamic, 1, 0},
    {"batch", cmd_batch, 1, 1},
};

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    for (int i = 2; i < argc; i++) /* obscura COMMAND ... --help */
        if ((!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) && usage_of(stdout, cmd))
            return EXIT_OK;
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(cmd, commands[i].name)) {
            /* before any context or thread: it may set LP_NUM_THREADS */
            int n = commands[i].threads ? cli_take_threads(cmd, argc - 2, argv + 2) : argc - 2;
            if (commands[i].memory)
                n = cli_take_max_memory(cmd, n, argv + 2);
            return commands[i].run(n, argv + 2);
        }
    if (!strcmp(cmd, "help") || !strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
        usage(stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "version") || !strcmp(cmd, "--version")) {
        printf("obscura %s\n", OBS_VERSION);
        return EXIT_OK;
    }
    die_usage("unknown command '%s'", cmd);
    return EXIT_USAGE;
}
