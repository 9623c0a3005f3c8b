#include "render/text.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include <stdlib.h>
#include <string.h>

enum { FIRST = 32, LAST = 126, GLYPHS = LAST - FIRST + 1 };

typedef struct glyph {
    int left, top, advance; /* bearing and advance in pixels */
    int width, rows;
    uint8_t *coverage; /* width * rows, 0..255 */
} glyph;

struct cm_font {
    int ascent, height;
    glyph g[GLYPHS];
};

static const glyph *glyph_of(const cm_font *f, char c)
{
    const unsigned char u = (unsigned char)c;
    return &f->g[(u >= FIRST && u <= LAST ? u : '?') - FIRST];
}

static int copy_glyph(FT_Face face, unsigned long code, glyph *g)
{
    if (FT_Load_Char(face, code, FT_LOAD_RENDER))
        return -1;
    const FT_GlyphSlot s = face->glyph;
    g->left = s->bitmap_left;
    g->top = s->bitmap_top;
    g->advance = (int)((s->advance.x + 32) >> 6);
    g->width = (int)s->bitmap.width;
    g->rows = (int)s->bitmap.rows;
    g->coverage = malloc((size_t)g->width * (size_t)g->rows + 1);
    if (!g->coverage)
        return -1;
    for (int r = 0; r < g->rows; r++)
        memcpy(g->coverage + (size_t)r * (size_t)g->width,
               s->bitmap.buffer + (ptrdiff_t)r * s->bitmap.pitch, (size_t)g->width);
    return 0;
}

cm_status cm_font_open(const char *path, int pixel_size, cm_font **out, char *msg, size_t msg_size)
{
    *out = NULL;
    FT_Library lib = NULL;
    FT_Face face = NULL;
    cm_font *f = calloc(1, sizeof *f);
    cm_status st = CM_OK;
    if (!f)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a font");
    if (FT_Init_FreeType(&lib))
        st = cm_fail(CM_ERENDER, msg, msg_size, "FreeType failed to start");
    else if (FT_New_Face(lib, path, 0, &face))
        st = cm_fail(CM_EIO, msg, msg_size,
                     "cannot open the font %s (install fonts-dejavu-core, or set CELLMAP_FONT "
                     "to a TrueType file)",
                     path);
    else if (FT_Set_Pixel_Sizes(face, 0, (FT_UInt)pixel_size))
        st = cm_fail(CM_ERENDER, msg, msg_size, "the font %s has no size %d", path, pixel_size);
    for (int c = FIRST; c <= LAST && st == CM_OK; c++)
        if (copy_glyph(face, (unsigned long)c, &f->g[c - FIRST]) != 0)
            st = cm_fail(CM_ERENDER, msg, msg_size, "cannot draw '%c' with the font %s", c, path);
    if (st == CM_OK) {
        f->ascent = (int)((face->size->metrics.ascender + 32) >> 6);
        f->height = (int)((face->size->metrics.height + 32) >> 6);
    }
    if (face)
        FT_Done_Face(face);
    if (lib)
        FT_Done_FreeType(lib);
    if (st != CM_OK) {
        cm_font_close(f);
        return st;
    }
    *out = f;
    return CM_OK;
}

void cm_font_close(cm_font *f)
{
    if (!f)
        return;
    for (int k = 0; k < GLYPHS; k++)
        free(f->g[k].coverage);
    free(f);
}

int cm_font_ascent(const cm_font *f) { return f->ascent; }
int cm_font_height(const cm_font *f) { return f->height; }

int cm_font_width(const cm_font *f, const char *text)
{
    int w = 0;
    for (const char *p = text; *p; p++)
        w += glyph_of(f, *p)->advance;
    return w;
}

static void blend_glyph(const glyph *g, int x0, int y0, cm_rgb c, uint8_t *rgba, int width,
                        int height)
{
    for (int r = 0; r < g->rows; r++) {
        const int y = y0 + r;
        if (y < 0 || y >= height)
            continue;
        for (int k = 0; k < g->width; k++) {
            const int x = x0 + k;
            const unsigned a = g->coverage[(size_t)r * (size_t)g->width + (size_t)k];
            if (x < 0 || x >= width || a == 0)
                continue;
            uint8_t *p = rgba + 4 * ((size_t)y * (size_t)width + (size_t)x);
            p[0] = (uint8_t)((c.r * a + p[0] * (255 - a) + 127) / 255);
            p[1] = (uint8_t)((c.g * a + p[1] * (255 - a) + 127) / 255);
            p[2] = (uint8_t)((c.b * a + p[2] * (255 - a) + 127) / 255);
        }
    }
}

void cm_font_draw(const cm_font *f, const char *text, int x, int y, cm_rgb colour, uint8_t *rgba,
                  int width, int height)
{
    for (const char *p = text; *p; p++) {
        const glyph *g = glyph_of(f, *p);
        blend_glyph(g, x + g->left, y - g->top, colour, rgba, width, height);
        x += g->advance;
    }
}
