/* render/text.h - labels drawn with FreeType from a TrueType font file.
 *
 * We use FreeType and DejaVu Sans (Debian: libfreetype-dev, fonts-dejavu-core)
 * rather than an embedded bitmap font: one scalable font serves a 300-pixel
 * thumbnail and an 8192-pixel poster alike, and it is antialiased. Glyphs
 * are rasterised once per size and blended with integer arithmetic, so the
 * same font file and library give the same bytes.
 * Text is ASCII; other bytes are drawn as '?'. Not thread-safe per font.
 */
#ifndef CM_RENDER_TEXT_H
#define CM_RENDER_TEXT_H

#include <stdint.h>

#include "cellmap/status.h"
#include "render/palette.h"

typedef struct cm_font cm_font;

/* Opens the font at a pixel size (the height of an em). */
cm_status cm_font_open(const char *path, int pixel_size, cm_font **out, char *msg, size_t msg_size);
void cm_font_close(cm_font *f); /* NULL-safe */

int cm_font_ascent(const cm_font *f);                  /* pixels above the baseline */
int cm_font_height(const cm_font *f);                  /* line height in pixels */
int cm_font_width(const cm_font *f, const char *text); /* advance of the text */

/* Blends the text into an RGBA image (row 0 at the top) with its baseline
 * at row y and its left edge at column x; clipped to the image. */
void cm_font_draw(const cm_font *f, const char *text, int x, int y, cm_rgb colour, uint8_t *rgba,
                  int width, int height);

#endif
