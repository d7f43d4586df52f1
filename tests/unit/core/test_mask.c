/* Object masks on real files: the Cryptomatte sample images of the
 * specification's repository (tests/data/crypto.SOURCE.txt) and the
 * Arnold sample's integer id channel.  Every expected mask is made here
 * by decoding the ranks independently (the channels read one by one, the
 * IDs from the manifest's hex text parsed here). */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/crypto.h"
#include "obscura/deep.h"
#include "obscura/mask.h"

#define CORNELL TESTDATA "/crypto_cornell_crop.exr"
#define SPECIAL TESTDATA "/crypto_special_chars.exr"
#define SIDECAR TESTDATA "/crypto_sidecar/sidecar_manifest.exr"
#define ARNOLD TESTDATA "/arnold_sample2.exr"
#define BLENDER TESTDATA "/small/room_masks.exr"

/* MurmurHash3_x86_32's published vectors (seed 0 unless given), and
 * names against the IDs the files' manifests hold. */
static void test_murmur3(void **state)
{
    (void)state;
    assert_int_equal(obs_murmur3_32("", 0, 0), 0u);
    assert_int_equal(obs_murmur3_32("", 0, 1), 0x514e28b7u);
    assert_int_equal(obs_murmur3_32("hello", 5, 0), 0x248bfa47u);
    assert_int_equal(obs_murmur3_32("The quick brown fox jumps over the lazy dog", 43, 0),
                     0x2e4ff723u);
    /* from the manifests of the sample frames */
    assert_int_equal(obs_crypto_name_id("rect_[_top"), 0xc1fa3f1fu);
    assert_int_equal(obs_crypto_name_id("sphere_?_2"), 0x86de553au);
    assert_int_equal(obs_crypto_name_id("\xd1\x80\xd0\xb0\xd0\xb2\xd0\xbd\xd0\xb8\xd0\xbd\xd0\xb0"),
                     0x9623511eu); /* "равнина" */
}

/* The special_chars sample: quotes, a slash, commas and Cyrillic
 * in the names; every ID is its name's hash. */
static void test_special_chars(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_crypto_info ci;
    assert_int_equal(obs_crypto_describe(SPECIAL, NULL, 0, &ci, err), OBS_OK);
    assert_int_equal(ci.layer_count, 1);
    const obs_crypto_layer *L = &ci.layers[0];
    assert_string_equal(L->name, "special_chars");
    assert_string_equal(L->manifest_error, "");
    assert_int_equal(L->rank_sets, 3);
    assert_int_equal(L->red_style, 1);
    assert_int_equal(L->entry_count, 4);
    const char *want[] = {"name containing a \"quote\"  ", "name_containing/slash",
                          "\xd1\x80\xd0\xb0\xd0\xb2\xd0\xbd\xd0\xb8\xd0\xbd\xd0\xb0",
                          "name, with, comma"};
    for (int k = 0; k < 4; k++) {
        int found = -1;
        for (int i = 0; i < L->entry_count; i++)
            if (!strcmp(L->names[i], want[k]))
                found = i;
        assert_true(found >= 0);
        assert_int_equal(L->ids[found], obs_crypto_name_id(want[k]));
    }
    obs_crypto_info_free(&ci);
    /* a name with commas, escaped in the selector, matches pixels */
    obs_image w = {0};
    assert_int_equal(obs_mask_plane(SPECIAL, NULL, 0, "name\\, with\\, comma", NULL, &w, NULL, err),
                     OBS_OK);
    double sum = 0.0;
    for (int i = 0; i < w.width * w.height; i++)
        sum += w.data[i];
    assert_true(sum > 1.0);
    obs_image_free(&w);
    /* '?' takes one character, two bytes here; '*' runs over them */
    assert_int_equal(obs_mask_plane(SPECIAL, NULL, 0, "?\xd0\xb0\xd0\xb2\xd0\xbd\xd0\xb8\xd0\xbd\xd0\xb0", NULL, &w,
                                    NULL, err),
                     OBS_OK);
    obs_image_free(&w);
    assert_int_equal(obs_mask_plane(SPECIAL, NULL, 0, "*\xd0\xbd?", NULL, &w, NULL, err), OBS_OK);
    obs_image_free(&w);
    /* a pattern of many stars against every name: no match, and an
     * answer (the matcher backtracks to the last star only) */
    char many[128] = "";
    for (int k = 0; k < 40; k++)
        strcat(many, "*a");
    strcat(many, "*q");
    assert_int_equal(obs_mask_plane(SPECIAL, NULL, 0, many, NULL, &w, NULL, err),
                     OBS_INVALID_ARGUMENT);
    /* a name not in the manifest is an error that lists the names */
    assert_int_equal(obs_mask_plane(SPECIAL, NULL, 0, "no_such_name", NULL, &w, NULL, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "name_containing/slash"));
}

static uint32_t bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

/* The matte of ids in layer (channels layerNN.RGBA, or .rgba where lower),
 * decoded here: the sum over the six ranks of the coverage where the rank's
 * ID is one of them. */
static float *decode_layer(const char *path, const char *layer, int lower, const uint32_t *ids,
                           int nids, int *w, int *h)
{
    char err[OBS_ERR_LEN];
    float *m = NULL;
    for (int s = 0; s < 3; s++)
        for (int r = 0; r < 2; r++) {
            char chi[96], chc[96];
            snprintf(chi, sizeof chi, "%s%02d.%s", layer, s, r ? (lower ? "b" : "B") : (lower ? "r" : "R"));
            snprintf(chc, sizeof chc, "%s%02d.%s", layer, s, r ? (lower ? "a" : "A") : (lower ? "g" : "G"));
            obs_image id = {0}, cov = {0};
            assert_int_equal(obs_exr_read_channel(path, chi, NULL, &id, err), OBS_OK);
            assert_int_equal(obs_exr_read_channel(path, chc, NULL, &cov, err), OBS_OK);
            if (!m) {
                *w = id.width;
                *h = id.height;
                m = calloc((size_t)id.width * id.height, sizeof *m);
            }
            for (int i = 0; i < id.width * id.height; i++)
                for (int k = 0; k < nids; k++)
                    if (bits(id.data[i]) == ids[k])
                        m[i] += cov.data[i];
            obs_image_free(&id);
            obs_image_free(&cov);
        }
    for (int i = 0; i < *w * *h; i++)
        m[i] = m[i] > 1.0f ? 1.0f : m[i];
    return m;
}

static float *decode(const char *path, const uint32_t *ids, int nids, int *w, int *h)
{
    return decode_layer(path, "uCryptoWildcard", 0, ids, nids, w, h);
}

/* Blender's Cryptomatte object layer (tests/data/small/README.md): ranks in
 * lower case (ViewLayer.CryptoObject00.r/g/b/a), the table's matte as
 * decoded here, with anti-aliased edges. */
static void test_blender_lower_case(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_crypto_info ci;
    assert_int_equal(obs_crypto_describe(BLENDER, NULL, 0, &ci, err), OBS_OK);
    assert_int_equal(ci.layer_count, 1);
    const obs_crypto_layer *L = &ci.layers[0];
    assert_string_equal(L->name, "ViewLayer.CryptoObject");
    assert_int_equal(L->rank_sets, 3);
    assert_int_equal(L->red_style, 2);
    assert_int_equal(L->entry_count, 7);
    obs_crypto_info_free(&ci);
    const uint32_t table = obs_crypto_name_id("table");
    obs_image w = {0};
    int W = 0, H = 0, covered = 0, partial = 0;
    assert_int_equal(obs_mask_plane(BLENDER, NULL, 0, "table", NULL, &w, NULL, err), OBS_OK);
    float *m = decode_layer(BLENDER, "ViewLayer.CryptoObject", 1, &table, 1, &W, &H);
    assert_int_equal(w.width, W);
    assert_int_equal(w.height, H);
    for (int i = 0; i < W * H; i++) {
        assert_true(fabsf(w.data[i] - m[i]) < 1e-6f);
        covered += m[i] > 0.0f;
        partial += m[i] > 0.0f && m[i] < 1.0f;
    }
    assert_true(covered > 100);
    assert_true(partial > 10);
    free(m);
    obs_image_free(&w);
}

static void expect_mask(const char *selector, const uint32_t *ids, int nids)
{
    char err[OBS_ERR_LEN];
    obs_image w = {0}, dom = {0};
    int W = 0, H = 0;
    assert_int_equal(obs_mask_plane(CORNELL, NULL, 0, selector, NULL, &w, &dom, err), OBS_OK);
    float *m = decode(CORNELL, ids, nids, &W, &H);
    assert_int_equal(w.width, W);
    assert_int_equal(w.height, H);
    int covered = 0, partial = 0;
    for (int i = 0; i < W * H; i++) {
        assert_true(fabsf(w.data[i] - m[i]) < 1e-6f);
        covered += m[i] > 0.0f;
        partial += m[i] > 0.0f && m[i] < 1.0f; /* anti-aliased edges keep their coverage */
    }
    assert_true(covered > 100);
    assert_true(partial > 10);
    assert_non_null(dom.data);
    free(m);
    obs_image_free(&w);
    obs_image_free(&dom);
}

/* Wildcards against literal '*' and '?' in the names: the V-Ray
 * cornell box frame of the specification's wildcard test. */
static void test_cornell_selectors(void **state)
{
    (void)state;
    /* IDs as the manifest's text gives them */
    const uint32_t star = (uint32_t)strtoul("5def0d04", NULL, 16); /* has_*_asterisk */
    const uint32_t n = (uint32_t)strtoul("976d3582", NULL, 16);    /* has_n_asterisk */
    const uint32_t top = (uint32_t)strtoul("c1fa3f1f", NULL, 16);  /* rect_[_top */
    const uint32_t bot = (uint32_t)strtoul("c2f7d6c0", NULL, 16);  /* rect_][_bot */
    const uint32_t both[] = {star, n};
    expect_mask("has_\\*_asterisk", &star, 1); /* escaped: the one name */
    expect_mask("has_*_asterisk", both, 2);    /* wildcard: both */
    const uint32_t rects[] = {top, bot};
    expect_mask("rect_*", rects, 2);
    expect_mask("@uCryptoWildcard:rect_[_top,rect_][_bot", rects, 2);
    char err[OBS_ERR_LEN];
    obs_image w = {0};
    /* "!": everything but */
    int W = 0, H = 0;
    float *m = decode(CORNELL, rects, 2, &W, &H);
    assert_int_equal(obs_mask_plane(CORNELL, NULL, 0, "!rect_*", NULL, &w, NULL, err), OBS_OK);
    for (int i = 0; i < W * H; i++)
        assert_true(fabsf(w.data[i] - (1.0f - m[i])) < 1e-6f);
    free(m);
    obs_image_free(&w);
    assert_int_equal(obs_mask_plane(CORNELL, NULL, 0, "@nolayer:x", NULL, &w, NULL, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "uCryptoWildcard"));
}

/* A side-car manifest read beside the image, and a clear error when it
 * is not there. */
static void test_sidecar(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_crypto_info ci;
    assert_int_equal(obs_crypto_describe(SIDECAR, NULL, 0, &ci, err), OBS_OK);
    assert_int_equal(ci.layer_count, 1);
    assert_string_equal(ci.layers[0].manif_file, "sidecar_manifest.crypto_asset.json");
    assert_string_equal(ci.layers[0].manifest_error, "");
    assert_int_equal(ci.layers[0].entry_count, 8);
    obs_crypto_info_free(&ci);
    obs_image w = {0};
    assert_int_equal(obs_mask_plane(SIDECAR, NULL, 0, "leftAsset", NULL, &w, NULL, err), OBS_OK);
    obs_image_free(&w);

    /* the image alone in a folder */
    char dir[] = "/tmp/obs_sidecar_XXXXXX", path[256];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/sidecar_manifest.exr", dir);
    FILE *in = fopen(SIDECAR, "rb"), *out = fopen(path, "wb");
    assert_non_null(in);
    assert_non_null(out);
    char buf[4096];
    size_t k;
    while ((k = fread(buf, 1, sizeof buf, in)) > 0)
        assert_int_equal(fwrite(buf, 1, k, out), k);
    fclose(in);
    fclose(out);
    assert_int_equal(obs_mask_plane(path, NULL, 0, "leftAsset", NULL, &w, NULL, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "sidecar_manifest.crypto_asset.json"));
    assert_non_null(strstr(err, "missing"));
    assert_null(w.data);
    unlink(path);
    rmdir(dir);
}

/* The Arnold sample's id channel (deep, uint): read at each pixel's front
 * sample; every covered pixel has exactly one of the IDs 1..4. */
static void test_arnold_id(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_deep_image d;
    assert_int_equal(obs_deep_read_exr(ARNOLD, NULL, &d, err), OBS_OK);
    obs_image all = {0}, one[4] = {{0}};
    assert_int_equal(obs_mask_plane(ARNOLD, NULL, 0, "id:id=1-4", NULL, &all, NULL, err), OBS_OK);
    assert_int_equal(all.width, d.width);
    for (int k = 0; k < 4; k++) {
        char sel[32];
        snprintf(sel, sizeof sel, "id:id=%d", k + 1);
        assert_int_equal(obs_mask_plane(ARNOLD, NULL, 0, sel, NULL, &one[k], NULL, err), OBS_OK);
    }
    int counts[4] = {0};
    for (int i = 0; i < d.width * d.height; i++) {
        int has = d.offset[i + 1] > d.offset[i];
        assert_true(all.data[i] == (float)has);
        float s = 0.0f;
        for (int k = 0; k < 4; k++) {
            assert_true(one[k].data[i] == 0.0f || one[k].data[i] == 1.0f);
            s += one[k].data[i];
            counts[k] += one[k].data[i] > 0.0f;
        }
        assert_true(s == all.data[i]);
    }
    for (int k = 0; k < 4; k++) {
        assert_true(counts[k] > 1000); /* each of the four objects is seen */
        obs_image_free(&one[k]);
    }
    obs_image_free(&all);
    obs_deep_free(&d);
    /* a channel the file lacks */
    assert_int_equal(obs_mask_plane(ARNOLD, NULL, 0, "id:IndexOB=1", NULL, &all, NULL, err),
                     OBS_MISSING_CHANNEL);
}

/* Integer ID channels by name: Arnold's id, Blender's IndexOB under its
 * view layer with its one-letter channel; not depth or normals. */
static void test_id_channel_names(void **state)
{
    (void)state;
    assert_true(obs__crypto_is_id_channel("id"));
    assert_true(obs__crypto_is_id_channel("ViewLayer.IndexOB.X"));
    assert_true(obs__crypto_is_id_channel("ViewLayer.IndexOB"));
    assert_true(obs__crypto_is_id_channel("IndexMA.V"));
    assert_false(obs__crypto_is_id_channel("ViewLayer.Depth.Z"));
    assert_false(obs__crypto_is_id_channel("N.X"));
    assert_false(obs__crypto_is_id_channel("R"));
}

static void test_bad_selectors(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_image w = {0};
    /* strtod reads "nan", "inf" and "nan-5" as numbers: no IDs (a NaN
     * range matched no pixel, silently) */
    const char *bad[] = {"", "!", "id:id", "id:id=", "id:id=3-1", "id:id=a", "a,,b", "x\\",
                         "matte:", "@:x", "id:id=nan", "id:id=1,inf", "id:id=nan-5",
                         "id:id=1-infinity"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        assert_int_equal(obs_mask_plane(CORNELL, NULL, 0, bad[i], NULL, &w, NULL, err),
                         OBS_INVALID_ARGUMENT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_murmur3),
        cmocka_unit_test(test_special_chars),
        cmocka_unit_test(test_cornell_selectors),
        cmocka_unit_test(test_blender_lower_case),
        cmocka_unit_test(test_sidecar),
        cmocka_unit_test(test_arnold_id),
        cmocka_unit_test(test_id_channel_names),
        cmocka_unit_test(test_bad_selectors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
