#include "render/gl.h"

#include <GL/osmesa.h>
#include <stdlib.h>

#include "render/gl_loader.h"

struct cm_gl {
    OSMesaContext ctx;
};

cm_status cm_gl_open(cm_gl **out, char *msg, size_t msg_size)
{
    *out = NULL;
    cm_status st = cm_gl_load(msg, msg_size);
    if (st != CM_OK)
        return st;
    *out = calloc(1, sizeof **out);
    if (!*out)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for an OSMesa context");
    (*out)->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 0, 0, 0, NULL);
    if (!(*out)->ctx) {
        free(*out);
        *out = NULL;
        return cm_fail(CM_ERENDER, msg, msg_size, "cannot create an OSMesa context");
    }
    return CM_OK;
}

void cm_gl_close(cm_gl *gl)
{
    if (!gl)
        return;
    OSMesaDestroyContext(gl->ctx);
    free(gl);
}

void *cm_gl_context(const cm_gl *gl) { return gl->ctx; }
