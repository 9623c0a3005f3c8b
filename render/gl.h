/* render/gl.h - an OSMesa context that outlives one figure. Creating a
 * context costs several milliseconds (llvmpipe compiles its shaders for
 * it); an explore session renders after every move and pays that once by
 * keeping one. Every figure sets all the GL state it uses, so a kept
 * context draws the same bytes as a new one. One thread at a time. */
#ifndef CM_RENDER_GL_H
#define CM_RENDER_GL_H

#include <stddef.h>

#include "cellmap/status.h"

typedef struct cm_gl cm_gl;

cm_status cm_gl_open(cm_gl **out, char *msg, size_t msg_size);
void cm_gl_close(cm_gl *gl); /* NULL-safe */

/* The context (an OSMesaContext) for render/ modules. */
void *cm_gl_context(const cm_gl *gl);

#endif
