/* render/gl_loader.h - OSMesa loaded on demand (see gl_loader.c). */
#ifndef CM_RENDER_GL_LOADER_H
#define CM_RENDER_GL_LOADER_H

#include <stddef.h>

#include "cellmap/status.h"

/* Loads OSMesa and binds the GL functions render/ calls, once per process
 * (thread-safe; later calls only report the first one's outcome). No GL or
 * OSMesa function may be called before it succeeded. CM_ERENDER naming
 * the library when it is missing. */
cm_status cm_gl_load(char *msg, size_t msg_size);

#endif
