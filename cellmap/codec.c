#include "cellmap/codec.h"

#include <stdlib.h>
#include <string.h>
#include <zstd.h>

/* Level 1: pages compress to 1-2 bytes per cell already (Fig. 4.16 and 4.21
 * regions), and higher levels cost far more time than they save bytes. */
#define CODEC_LEVEL 1

size_t cm_codec_bound(size_t bytes) { return ZSTD_compressBound(bytes) + 32; /* + checksum */ }

static void store_value(void *v, size_t i, int width, uint64_t x)
{
    if (width == 4) {
        const uint32_t y = (uint32_t)x;
        memcpy((unsigned char *)v + 4 * i, &y, 4);
    } else {
        memcpy((unsigned char *)v + 8 * i, &x, 8);
    }
}

/* Step 1 and 2 for uint32 arrays: the hot path of every page written.
 * restrict: planes may not alias v, so the loop vectorises. */
static void planes_u32(const uint32_t *restrict v, size_t n, int64_t first_index,
                       unsigned char *restrict planes)
{
    const uint32_t base = first_index >= 0 ? (uint32_t)first_index : 0;
    const uint32_t relative = first_index >= 0;
    for (size_t i = 0; i < n; i++) {
        const uint32_t x = v[i] - relative * (base + (uint32_t)i);
        planes[i] = (unsigned char)x;
        planes[n + i] = (unsigned char)(x >> 8);
        planes[2 * n + i] = (unsigned char)(x >> 16);
        planes[3 * n + i] = (unsigned char)(x >> 24);
    }
}

/* Step 2 for 64-bit values (exit tables, open nodes): one pass writing
 * the eight planes, which vectorises; a loop over the bytes of each value
 * stored them one at a time. */
static void planes_u64(const unsigned char *restrict v, size_t n, unsigned char *restrict planes)
{
    for (size_t i = 0; i < n; i++) {
        uint64_t x;
        memcpy(&x, v + 8 * i, 8);
        for (size_t b = 0; b < 8; b++)
            planes[b * n + i] = (unsigned char)(x >> (8 * b));
    }
}

/* The reverse of planes_u32: the hot path of every page read. */
static void unplanes_u32(const unsigned char *planes, size_t n, int64_t first_index, uint32_t *v)
{
    const uint32_t base = first_index >= 0 ? (uint32_t)first_index : 0;
    const uint32_t relative = first_index >= 0;
    for (size_t i = 0; i < n; i++)
        v[i] = ((uint32_t)planes[i] | (uint32_t)planes[n + i] << 8 |
                (uint32_t)planes[2 * n + i] << 16 | (uint32_t)planes[3 * n + i] << 24) +
               relative * (base + (uint32_t)i);
}

struct cm_codec_ctx {
    ZSTD_CCtx *zstd;
};

cm_status cm_codec_ctx_new(cm_codec_ctx **out)
{
    cm_codec_ctx *ctx = malloc(sizeof *ctx);
    ZSTD_CCtx *zstd = ZSTD_createCCtx();
    /* the frame's checksum makes a damaged BLOB an error when it is read */
    if (!ctx || !zstd || ZSTD_isError(ZSTD_CCtx_setParameter(zstd, ZSTD_c_compressionLevel,
                                                             CODEC_LEVEL)) ||
        ZSTD_isError(ZSTD_CCtx_setParameter(zstd, ZSTD_c_checksumFlag, 1))) {
        ZSTD_freeCCtx(zstd);
        free(ctx);
        return CM_ENOMEM;
    }
    ctx->zstd = zstd;
    *out = ctx;
    return CM_OK;
}

void cm_codec_ctx_free(cm_codec_ctx *ctx)
{
    if (!ctx)
        return;
    ZSTD_freeCCtx(ctx->zstd);
    free(ctx);
}

cm_status cm_codec_encode_with(cm_codec_ctx *ctx, const void *v, size_t n, int width,
                               int64_t first_index, void *scratch, void *out, size_t out_cap,
                               size_t *len)
{
    unsigned char *planes = scratch;
    if (width == 4)
        planes_u32(v, n, first_index, planes);
    else
        planes_u64(v, n, planes);
    const size_t r = ZSTD_compress2(ctx->zstd, out, out_cap, planes, n * (size_t)width);
    if (ZSTD_isError(r))
        return CM_ENOMEM;
    *len = r;
    return CM_OK;
}

cm_status cm_codec_encode(const void *v, size_t n, int width, int64_t first_index, void *scratch,
                          void *out, size_t out_cap, size_t *len)
{
    cm_codec_ctx *ctx;
    if (cm_codec_ctx_new(&ctx) != CM_OK)
        return CM_ENOMEM;
    const cm_status st =
        cm_codec_encode_with(ctx, v, n, width, first_index, scratch, out, out_cap, len);
    cm_codec_ctx_free(ctx);
    return st;
}

cm_status cm_codec_decode(const void *in, size_t len, size_t n, int width, int64_t first_index,
                          void *scratch, void *v)
{
    unsigned char *planes = scratch;
    const size_t bytes = n * (size_t)width;
    const unsigned long long size = ZSTD_getFrameContentSize(in, len);
    if (size != bytes)
        return CM_EFORMAT;
    const size_t r = ZSTD_decompress(planes, bytes, in, len);
    if (ZSTD_isError(r) || r != bytes)
        return CM_EFORMAT;
    if (width == 4) {
        unplanes_u32(planes, n, first_index, v);
        return CM_OK;
    }
    for (size_t i = 0; i < n; i++) {
        uint64_t x = 0;
        for (int b = 0; b < width; b++)
            x |= (uint64_t)planes[(size_t)b * n + i] << (8 * b);
        if (first_index >= 0)
            x = (uint32_t)(x + (uint64_t)first_index + i);
        store_value(v, i, width, x);
    }
    return CM_OK;
}
