/* render/gl_loader.h - the GL stack loaded on demand (see gl_loader.c):
 * OSMesa, or EGL on Mesa's software device (llvmpipe), behind the same GL
 * functions. */
#ifndef CM_RENDER_GL_LOADER_H
#define CM_RENDER_GL_LOADER_H

#include <stddef.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "cellmap/status.h"

typedef enum cm_gl_backend { CM_GL_NONE = 0, CM_GL_OSMESA, CM_GL_EGL } cm_gl_backend;

/* Loads the backend and binds the GL functions render/ calls, once per
 * process (thread-safe; later calls only report the first one's outcome).
 * CELLMAP_GL=osmesa or egl chooses; unset or empty, OSMesa where it loads
 * (the design's renderer), else EGL. No GL, OSMesa or EGL function may be
 * called before it succeeded. CM_ERENDER naming what is missing. */
cm_status cm_gl_load(char *msg, size_t msg_size);

/* The backend loaded (CM_GL_NONE before a successful cm_gl_load). */
cm_gl_backend cm_gl_loaded(void);

/* EGL's entry points, after cm_gl_load chose EGL. */
typedef struct cm_egl_api {
    PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT;
    PFNEGLQUERYDEVICESTRINGEXTPROC QueryDeviceStringEXT;
    PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT;
    EGLBoolean(EGLAPIENTRYP Initialize)(EGLDisplay, EGLint *, EGLint *);
    EGLBoolean(EGLAPIENTRYP BindAPI)(EGLenum);
    EGLBoolean(EGLAPIENTRYP ChooseConfig)(EGLDisplay, const EGLint *, EGLConfig *, EGLint,
                                          EGLint *);
    EGLContext(EGLAPIENTRYP CreateContext)(EGLDisplay, EGLConfig, EGLContext, const EGLint *);
    EGLBoolean(EGLAPIENTRYP DestroyContext)(EGLDisplay, EGLContext);
    EGLBoolean(EGLAPIENTRYP MakeCurrent)(EGLDisplay, EGLSurface, EGLSurface, EGLContext);
    EGLint(EGLAPIENTRYP GetError)(void);
} cm_egl_api;
const cm_egl_api *cm_egl(void);

#endif
