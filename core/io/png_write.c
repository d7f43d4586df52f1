/* PNG output through libpng: 8 or 16 bit, grey, RGB or RGBA, its
 * transfer function tagged (sRGB, or linear by gAMA 1.0 and cICP) and
 * its provenance in text chunks.  libpng reports errors by longjmp; they
 * come back as a status, never a crash and never a line on stderr. */
#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "obscura/io.h"
#include "out_file.h"
#include "provenance.h"

/* libpng states the cause of an error in a warning just before it. */
typedef struct png_msgs {
    char error[OBS_ERR_LEN];
    char warning[200];
} png_msgs;

static void png_error_fn(png_structp png, png_const_charp msg)
{
    png_msgs *m = png_get_error_ptr(png);
    snprintf(m->error, sizeof m->error, "libpng: %s%s%s%s", msg, m->warning[0] ? " (" : "",
             m->warning, m->warning[0] ? ")" : "");
    png_longjmp(png, 1);
}

static void png_warning_fn(png_structp png, png_const_charp msg)
{
    png_msgs *m = png_get_error_ptr(png);
    snprintf(m->warning, sizeof m->warning, "%s", msg);
}

/* Linear [0,1] to the sRGB transfer curve (IEC 61966-2-1). */
static double srgb_encode(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

const char *const obs_png_transfers[] = {"srgb", "linear", NULL};

obs_png_transfer obs_png_transfer_parse(const char *name)
{
    for (int i = 0; name && obs_png_transfers[i]; i++)
        if (!strcmp(name, obs_png_transfers[i]))
            return (obs_png_transfer)(i + 1);
    return OBS_PNG_TRANSFER_DEFAULT;
}

/* A display-referred colour over 1 (an HDR beauty's sky, a highlight):
 * scaled by its largest channel, so its hue and saturation stay, where
 * clamping each channel alone would shift them.  An infinite channel
 * takes 1, the finite ones 0. */
static void display_range(const float *src, double rgb[3])
{
    double m = 0.0;
    for (int c = 0; c < 3; c++) {
        rgb[c] = src[c] > 0.0f ? src[c] : 0.0; /* NaN becomes 0 too */
        m = rgb[c] > m ? rgb[c] : m;
    }
    if (m <= 1.0)
        return;
    for (int c = 0; c < 3; c++)
        rgb[c] = isinf(m) ? (isinf(rgb[c]) ? 1.0 : 0.0) : rgb[c] / m;
}

/* One row of float pixels to big-endian 8- or 16-bit samples. */
static void convert_row(const float *src, unsigned char *dst, int width, int channels, int bits, int srgb,
                        int display)
{
    const double max = bits == 16 ? 65535.0 : 255.0;
    const int colours = channels >= 3 ? 3 : 1; /* alpha stays linear */
    double rgb[3];
    for (int i = 0; i < width * channels; i++) {
        const int c = i % channels;
        double v = src[i];
        if (display && colours == 3 && c == 0)
            display_range(src + i, rgb);
        if (display && colours == 3 && c < 3)
            v = rgb[c];
        v = v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0; /* NaN becomes 0 too */
        if (srgb && c < colours)
            v = srgb_encode(v);
        unsigned q = (unsigned)lrint(v * max);
        if (bits == 16) {
            dst[2 * i] = (unsigned char)(q >> 8);
            dst[2 * i + 1] = (unsigned char)(q & 0xff);
        } else {
            dst[i] = (unsigned char)q;
        }
    }
}

/* The chunks that say how to read the values: sRGB (with the gAMA and
 * cHRM the PNG spec asks of an sRGB encoder, for readers that know only
 * those), or linear: gAMA 1.0, Rec. 709 cHRM on colour, and cICP (PNG
 * third edition: BT.709 primaries 1, linear transfer 8, RGB matrix 0,
 * full range), which libpng 1.6 writes as an unknown chunk. */
static void tag_transfer(png_structp png, png_infop info, int srgb, int colour)
{
    static png_byte cicp_name[5] = "cICP";
    static png_byte cicp_linear[4] = {1, 8, 0, 1};
    if (srgb) {
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
        return;
    }
    png_set_gAMA(png, info, 1.0);
    if (colour)
        png_set_cHRM(png, info, 0.3127, 0.3290, 0.64, 0.33, 0.30, 0.60, 0.15, 0.06);
    png_unknown_chunk cicp = {{'c', 'I', 'C', 'P', 0}, cicp_linear, sizeof cicp_linear, PNG_HAVE_IHDR};
    png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_ALWAYS, cicp_name, 1);
    png_set_unknown_chunks(png, info, &cicp, 1);
}

/* The obscura/... keys as tEXt chunks, iTXt (UTF-8) for a value beyond
 * ASCII (a path in another script); libpng copies the strings. */
static void tag_provenance(png_structp png, png_infop info, const obs_provenance *p)
{
    obs__prov prov;
    png_text text[OBS__PROV_KEYS];
    obs__prov_build(p, &prov);
    memset(text, 0, sizeof text);
    for (int i = 0; i < prov.count; i++) {
        int ascii = 1;
        for (const unsigned char *c = (const unsigned char *)prov.value[i]; *c; c++)
            ascii &= *c < 0x80;
        text[i].compression = ascii ? PNG_TEXT_COMPRESSION_NONE : PNG_ITXT_COMPRESSION_NONE;
        text[i].key = (png_charp)prov.key[i];
        text[i].text = (png_charp)prov.value[i];
        text[i].text_length = strlen(prov.value[i]);
    }
    png_set_text(png, info, text, prov.count);
}

/* libpng's write callbacks for the in-memory stream. */
static void mem_write(png_structp png, png_bytep data, size_t len)
{
    obs__membuf *m = png_get_io_ptr(png);
    if (obs__membuf_write(m, m->size, data, len) != 0)
        png_error(png, "out of memory");
}

static void mem_flush(png_structp png)
{
    (void)png;
}

static const obs_png_options zero_options = {0};

/* Writes to `path`, or into `mem` when it is non-NULL (`path` then only
 * names the output in messages); `opt` is not NULL. */
static obs_status write_png(const char *path, obs__membuf *mem, const obs_image *img,
                            const obs_png_options *opt, char err[OBS_ERR_LEN])
{
    png_msgs msgs = {"", ""};
    char *const msg = msgs.error; /* what obs__fail() fills on our own errors */
    /* Written between setjmp and a possible longjmp, hence volatile. */
    FILE *volatile fp = NULL;
    unsigned char *volatile row = NULL;
    png_structp png = NULL;
    png_infop info = NULL;
    volatile obs_status st = OBS_OK;
    size_t rowbytes;
    obs__out_file out;

    const int bits = opt->bits ? opt->bits : 8;
    const int colour = img && img->channels >= 3, display = opt->display && colour;
    const int srgb = display || opt->transfer != OBS_PNG_TRANSFER_LINEAR;
    if (!path || !*path || !img || !img->data)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_png_write: no path or image");
    if (bits != 8 && bits != 16)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: PNG bit depth must be 8 or 16, not %d", path, bits);
    if (img->channels != 1 && img->channels != 3 && img->channels != 4)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: PNG needs 1, 3 or 4 channels, not %d", path,
                         img->channels);
    if (img->width <= 0 || img->height <= 0 || img->width > 0x7fffffff / 8)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: image size %dx%d", path, img->width, img->height);
    if (obs__size_mul3((size_t)img->width, (size_t)img->channels, (size_t)bits / 8, &rowbytes) != 0 ||
        !(row = malloc(rowbytes)))
        return obs__fail(err, OBS_NO_MEMORY, "%s: row of %d pixels", path, img->width);
    if (!mem && !(fp = fopen(obs__out_begin(&out, path), "wb"))) {
        st = obs__fail(msg, OBS_IO, "cannot create: %s", strerror(errno));
        goto fail;
    }
    png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &msgs, png_error_fn, png_warning_fn);
    if (!png || !(info = png_create_info_struct(png))) {
        st = obs__fail(msg, OBS_NO_MEMORY, "libpng could not start");
        goto fail;
    }
    if (setjmp(png_jmpbuf(png))) {
        st = OBS_IO; /* msgs was filled by png_error_fn */
        goto fail;
    }
    static const int types[] = {0, PNG_COLOR_TYPE_GRAY, 0, PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
    if (mem)
        png_set_write_fn(png, mem, mem_write, mem_flush);
    else
        png_init_io(png, fp);
    png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, bits,
                 types[img->channels], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    tag_transfer(png, info, srgb, colour);
    tag_provenance(png, info, opt->prov);
    png_write_info(png, info);
    for (int y = 0; y < img->height; y++) {
        const float *src = img->data + (size_t)y * (size_t)img->width * (size_t)img->channels;
        convert_row(src, row, img->width, img->channels, bits, srgb, display);
        png_write_row(png, row);
    }
    png_write_end(png, info);
fail:
    png_destroy_write_struct(&png, &info);
    if (fp && fclose(fp) != 0 && st == OBS_OK)
        st = obs__fail(msg, OBS_IO, "closing: %s", strerror(errno));
    free(row);
    /* renamed into place whole, or no truncated PNG left behind */
    if (fp)
        st = obs__out_end(&out, st, msg);
    if (st == OBS_OK)
        return OBS_OK;
    return obs__fail(err, st, "%s: %s", path, msg);
}

/* The options of the older calls: `srgb` for display colour, grey
 * linear either way. */
static obs_png_options legacy(int bits, int srgb)
{
    return (obs_png_options){.bits = bits, .transfer = OBS_PNG_TRANSFER_LINEAR, .display = srgb};
}

obs_status obs_png_write_ex(const char *path, const obs_image *img, const obs_png_options *opt,
                            char err[OBS_ERR_LEN])
{
    return write_png(path, NULL, img, opt ? opt : &zero_options, err);
}

obs_status obs_png_write(const char *path, const obs_image *img, int bits, int srgb,
                         char err[OBS_ERR_LEN])
{
    obs_png_options o = legacy(bits, srgb);
    return write_png(path, NULL, img, &o, err);
}

obs_status obs_png_write_ex_mem(const obs_image *img, const obs_png_options *opt, obs_bytes *out,
                                char err[OBS_ERR_LEN])
{
    obs__membuf mem = {0};
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_png_write_mem: no output");
    *out = (obs_bytes){0};
    obs_status st = write_png("(memory)", &mem, img, opt ? opt : &zero_options, err);
    if (st == OBS_OK)
        obs__membuf_take(&mem, out);
    free(mem.data);
    return st;
}

obs_status obs_png_write_mem(const obs_image *img, int bits, int srgb, obs_bytes *out,
                             char err[OBS_ERR_LEN])
{
    obs_png_options o = legacy(bits, srgb);
    return obs_png_write_ex_mem(img, &o, out, err);
}
