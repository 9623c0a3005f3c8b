/* cellmap/codec.h - the compressed arrays of .cmdb pages.
 *
 * An array of n values of `width` bytes (4: uint32, 8: int64) is stored as
 *   1. (uint32 images only) each value minus its cell's index in the region,
 *      modulo 2^32, so the smooth images of neighbouring cells become
 *      nearly equal numbers;
 *   2. little-endian bytes, split into `width` byte planes (all first bytes,
 *      then all second bytes, ...), which puts the mostly-zero high bytes
 *      together;
 *   3. one zstd frame (level 1) with its content size and checksum.
 * Decoding reverses the steps and checks the size, so a corrupt BLOB is an
 * error, never a wrong array. Thread-safe; the caller owns every buffer.
 */
#ifndef CM_CODEC_H
#define CM_CODEC_H

#include <stddef.h>
#include <stdint.h>

#include "cellmap/status.h"

/* Bytes an encoded array of `bytes` raw bytes may take. */
size_t cm_codec_bound(size_t bytes);

/* Encodes v[0..n) (width 4 or 8). first_index: the region index of v[0]
 * for image arrays (step 1 above), or -1 for plain arrays. scratch holds
 * n * width bytes. On success *len is the encoded size. */
cm_status cm_codec_encode(const void *v, size_t n, int width, int64_t first_index, void *scratch,
                          void *out, size_t out_cap, size_t *len);

/* A compression context to encode many arrays with (creating one per array
 * costs about a third of encoding a page). One thread at a time. */
typedef struct cm_codec_ctx cm_codec_ctx;
cm_status cm_codec_ctx_new(cm_codec_ctx **out);
void cm_codec_ctx_free(cm_codec_ctx *ctx);

/* cm_codec_encode with ctx. */
cm_status cm_codec_encode_with(cm_codec_ctx *ctx, const void *v, size_t n, int width,
                               int64_t first_index, void *scratch, void *out, size_t out_cap,
                               size_t *len);

/* Decodes an encoded array that must hold exactly n values of `width`
 * bytes; CM_EFORMAT if it does not. scratch holds n * width bytes. */
cm_status cm_codec_decode(const void *in, size_t len, size_t n, int width, int64_t first_index,
                          void *scratch, void *v);

#endif
