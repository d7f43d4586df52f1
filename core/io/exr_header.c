/* The header attributes of an input EXR carried into an output part:
 * every attribute of any type, except those that describe the pixels
 * of the part the writer lays out itself. */
#include <stdlib.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

/* Attributes of the storage layout: the writer sets these from what it
 * writes (channels, compression, windows, scanline order), or the
 * library does (chunkCount, type, name, version); a copied `tiles`
 * would describe a tiled part where a scanline part is written. */
static const char *const layout_attrs[] = {"channels", "compression", "dataWindow", "displayWindow",
                                           "lineOrder", "tiles", "chunkCount", "type",
                                           "name", "version", NULL};

int obs__exr_attr_is_layout(const char *name)
{
    for (const char *const *a = layout_attrs; *a; a++)
        if (!strcmp(name, *a))
            return 1;
    return 0;
}

/* One attribute through its typed setter (the library copies the value). */
static exr_result_t copy_one(exr_context_t out, int part, const exr_attribute_t *a)
{
    const char *n = a->name;
    switch (a->type) {
    case EXR_ATTR_BOX2I: return exr_attr_set_box2i(out, part, n, a->box2i);
    case EXR_ATTR_BOX2F: return exr_attr_set_box2f(out, part, n, a->box2f);
    case EXR_ATTR_CHLIST: return exr_attr_set_channels(out, part, n, a->chlist);
    case EXR_ATTR_CHROMATICITIES: return exr_attr_set_chromaticities(out, part, n, a->chromaticities);
    case EXR_ATTR_COMPRESSION: return exr_attr_set_compression(out, part, n, (exr_compression_t)a->uc);
    case EXR_ATTR_DOUBLE: return exr_attr_set_double(out, part, n, a->d);
    case EXR_ATTR_ENVMAP: return exr_attr_set_envmap(out, part, n, (exr_envmap_t)a->uc);
    case EXR_ATTR_FLOAT: return exr_attr_set_float(out, part, n, a->f);
    case EXR_ATTR_FLOAT_VECTOR:
        return exr_attr_set_float_vector(out, part, n, a->floatvector->length, a->floatvector->arr);
    case EXR_ATTR_INT: return exr_attr_set_int(out, part, n, a->i);
    case EXR_ATTR_KEYCODE: return exr_attr_set_keycode(out, part, n, a->keycode);
    case EXR_ATTR_LINEORDER: return exr_attr_set_lineorder(out, part, n, (exr_lineorder_t)a->uc);
    case EXR_ATTR_M33F: return exr_attr_set_m33f(out, part, n, a->m33f);
    case EXR_ATTR_M33D: return exr_attr_set_m33d(out, part, n, a->m33d);
    case EXR_ATTR_M44F: return exr_attr_set_m44f(out, part, n, a->m44f);
    case EXR_ATTR_M44D: return exr_attr_set_m44d(out, part, n, a->m44d);
    case EXR_ATTR_PREVIEW: return exr_attr_set_preview(out, part, n, a->preview);
    case EXR_ATTR_RATIONAL: return exr_attr_set_rational(out, part, n, a->rational);
    case EXR_ATTR_STRING: return exr_attr_set_string(out, part, n, a->string->str ? a->string->str : "");
    case EXR_ATTR_STRING_VECTOR: {
        const exr_attr_string_vector_t *sv = a->stringvector;
        if (sv->n_strings < 0)
            return EXR_ERR_INVALID_ATTR;
        const char **strs = malloc(((size_t)sv->n_strings + 1) * sizeof *strs);
        if (!strs)
            return EXR_ERR_OUT_OF_MEMORY;
        for (int i = 0; i < sv->n_strings; i++)
            strs[i] = sv->strings[i].str ? sv->strings[i].str : "";
        exr_result_t rv = exr_attr_set_string_vector(out, part, n, sv->n_strings, strs);
        free(strs);
        return rv;
    }
    case EXR_ATTR_TILEDESC: return exr_attr_set_tiledesc(out, part, n, a->tiledesc);
    case EXR_ATTR_TIMECODE: return exr_attr_set_timecode(out, part, n, a->timecode);
    case EXR_ATTR_V2I: return exr_attr_set_v2i(out, part, n, a->v2i);
    case EXR_ATTR_V2F: return exr_attr_set_v2f(out, part, n, a->v2f);
    case EXR_ATTR_V2D: return exr_attr_set_v2d(out, part, n, a->v2d);
    case EXR_ATTR_V3I: return exr_attr_set_v3i(out, part, n, a->v3i);
    case EXR_ATTR_V3F: return exr_attr_set_v3f(out, part, n, a->v3f);
    case EXR_ATTR_V3D: return exr_attr_set_v3d(out, part, n, a->v3d);
    case EXR_ATTR_OPAQUE:
        return exr_attr_set_user(out, part, n, a->type_name, a->opaque->size, a->opaque->packed_data);
    default: return EXR_ERR_INVALID_ATTR;
    }
}

exr_result_t obs__exr_copy_attrs(exr_context_t out, int part, exr_const_context_t src, int src_part,
                                 const char *const *skip, const char **failed)
{
    int32_t count = 0;
    exr_result_t rv = exr_get_attribute_count(src, src_part, &count);
    *failed = NULL;
    for (int32_t i = 0; rv == EXR_ERR_SUCCESS && i < count; i++) {
        const exr_attribute_t *a = NULL;
        int skipped = 0;
        if ((rv = exr_get_attribute_by_index(src, src_part, EXR_ATTR_LIST_FILE_ORDER, i, &a)) != EXR_ERR_SUCCESS)
            break;
        if (!a || !a->name || obs__exr_attr_is_layout(a->name))
            continue;
        for (const char *const *s = skip; s && *s; s++)
            skipped |= !strcmp(a->name, *s);
        if (!skipped && (rv = copy_one(out, part, a)) != EXR_ERR_SUCCESS)
            *failed = a->name;
    }
    return rv;
}

int obs__exr_attrs_long_names(exr_const_context_t src, int src_part)
{
    int32_t count = 0;
    if (exr_get_attribute_count(src, src_part, &count) != EXR_ERR_SUCCESS)
        return 0;
    for (int32_t i = 0; i < count; i++) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_index(src, src_part, EXR_ATTR_LIST_FILE_ORDER, i, &a) == EXR_ERR_SUCCESS && a &&
            (a->name_length > 31 || a->type_name_length > 31))
            return 1;
    }
    return 0;
}
