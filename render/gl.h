/* render/gl.h - a GL context that outlives one figure, on OSMesa or on EGL
 * (render/gl_loader.h chooses once per process). Creating a context costs
 * several milliseconds (llvmpipe compiles its shaders for it); an explore
 * session renders after every move and pays that once by keeping one.
 * Every figure sets all the GL state it uses, so a kept context draws the
 * same bytes as a new one. One thread at a time.
 *
 * Drawing goes tile by tile: cm_gl_target makes the context current on a
 * w x h rectangle of the caller's RGBA image (row 0 at the top, rows
 * row_pixels apart), cm_gl_window places the viewport and scissor on a
 * part of it, GL draws (projections as usual, y up), and cm_gl_done waits
 * for GL and leaves the pixels in the image. OSMesa draws straight into
 * the image, which Mesa renders with its rows top down (y flipped); EGL
 * draws into a framebuffer object on Mesa's software device (llvmpipe, as
 * OSMesa) flipped the same way (glClipControl's upper-left origin) and
 * reads it back, so both rasterise alike and give the same bytes. */
#ifndef CM_RENDER_GL_H
#define CM_RENDER_GL_H

#include <stddef.h>
#include <stdint.h>

#include "cellmap/status.h"

typedef struct cm_gl cm_gl;

cm_status cm_gl_open(cm_gl **out, char *msg, size_t msg_size);
void cm_gl_close(cm_gl *gl); /* NULL-safe */

/* "OSMesa" or "EGL": the backend the process draws with. */
const char *cm_gl_backend_name(const cm_gl *gl);

cm_status cm_gl_target(cm_gl *gl, uint8_t *origin, int row_pixels, int w, int h, char *msg,
                       size_t msg_size);
/* A w x h rectangle of the tile whose top left pixel is (x, y_top), rows
 * counted from the tile's top; it may reach beyond the tile. */
typedef struct cm_gl_rect {
    int x, y_top, w, h;
} cm_gl_rect;

/* The viewport on `view` and the scissor on `scissor`. */
void cm_gl_window(const cm_gl *gl, const cm_gl_rect *view, const cm_gl_rect *scissor);
cm_status cm_gl_done(cm_gl *gl, char *msg, size_t msg_size);

#endif
