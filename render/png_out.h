/* render/png_out.h - PNG files through libpng's classic API.
 *
 * cm_png_write writes an 8-bit RGB PNG (from an RGBA buffer, row 0 at the
 * top) with tEXt chunks recording provenance, first to PATH.tmp-PID, then
 * renamed over PATH: a reader never sees a half-written image. No time chunk
 * is written, so the same pixels and texts give the same bytes. dpi > 0 is
 * written as the image's resolution (pHYs, in pixels per metre, rounded);
 * 0 writes none.
 */
#ifndef CM_RENDER_PNG_OUT_H
#define CM_RENDER_PNG_OUT_H

#include <stdint.h>

#include "cellmap/status.h"

typedef struct cm_png_text {
    const char *key; /* 1..79 Latin-1 characters */
    const char *value;
} cm_png_text;

cm_status cm_png_write(const char *path, const uint8_t *rgba, int width, int height, double dpi,
                       const cm_png_text *texts, int n_texts, char *msg, size_t msg_size);

/* The PNG of an RGBA image (row 0 at the top) in memory, for embedding:
 * *out (the caller frees it) holds *size bytes. */
cm_status cm_png_encode(const uint8_t *rgba, int width, int height, uint8_t **out, size_t *size,
                        char *msg, size_t msg_size);

/* An 8-bit palette PNG: one index per pixel (row 0 at the top), palette of
 * n_colours RGB triples. Written the same way as cm_png_write. */
cm_status cm_png_write_indexed(const char *path, const uint8_t *index, int width, int height,
                               double dpi, const uint8_t *palette, int n_colours,
                               const cm_png_text *texts, int n_texts, char *msg, size_t msg_size);

#endif
