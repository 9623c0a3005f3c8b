/* render/gl_loader.c - OSMesa or EGL, and the GL functions render/ calls,
 * loaded when the first context is made (cm_gl_load), so that commands
 * which draw nothing never map Mesa and the LLVM it brings (about 50 MiB
 * and 20 ms at every start). Upstream Mesa removed OSMesa in 25.1; EGL on
 * Mesa's software device draws the same pixels with the same llvmpipe.
 *
 * Each function the renderer calls is defined here under its own name and
 * forwards to the library's entry point, so the drawing code reads as
 * plain GL. The table of entry points is filled once per process, like the
 * dynamic linker's own bindings, and never changes afterwards.
 */
#include "render/gl_loader.h"

#define GL_GLEXT_PROTOTYPES 1 /* the framebuffer functions' prototypes */
#include <GL/osmesa.h>
#include <dlfcn.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Every entry point that returns a value: type, name, parameters, arguments. */
#define CM_GL_VALUE_FUNCTIONS(X)                                                                   \
    X(OSMesaContext, OSMesaCreateContextExt,                                                       \
      (GLenum format, GLint depth, GLint stencil, GLint accum, OSMesaContext share),               \
      (format, depth, stencil, accum, share))                                                      \
    X(GLboolean, OSMesaMakeCurrent,                                                                \
      (OSMesaContext ctx, void *buffer, GLenum type, GLsizei width, GLsizei height),               \
      (ctx, buffer, type, width, height))                                                          \
    X(GLenum, glGetError, (void), ())

/* And the others. */
#define CM_GL_VOID_FUNCTIONS(X)                                                                    \
    X(void, OSMesaDestroyContext, (OSMesaContext ctx), (ctx))                                      \
    X(void, OSMesaPixelStore, (GLint pname, GLint value), (pname, value))                          \
    X(void, glBegin, (GLenum mode), (mode))                                                        \
    X(void, glEnd, (void), ())                                                                     \
    X(void, glVertex2d, (GLdouble x, GLdouble y), (x, y))                                          \
    X(void, glTexCoord2d, (GLdouble s, GLdouble t), (s, t))                                        \
    X(void, glColor3ub, (GLubyte r, GLubyte g, GLubyte b), (r, g, b))                              \
    X(void, glLineWidth, (GLfloat width), (width))                                                 \
    X(void, glPointSize, (GLfloat size), (size))                                                   \
    X(void, glLineStipple, (GLint factor, GLushort pattern), (factor, pattern))                    \
    X(void, glPixelStorei, (GLenum pname, GLint param), (pname, param))                            \
    X(void, glTexParameteri, (GLenum target, GLenum pname, GLint param), (target, pname, param))   \
    X(void, glTexImage2D,                                                                          \
      (GLenum target, GLint level, GLint internal, GLsizei width, GLsizei height, GLint border,     \
       GLenum format, GLenum type, const GLvoid *pixels),                                          \
      (target, level, internal, width, height, border, format, type, pixels))                      \
    X(void, glGenTextures, (GLsizei n, GLuint *textures), (n, textures))                           \
    X(void, glDeleteTextures, (GLsizei n, const GLuint *textures), (n, textures))                  \
    X(void, glBindTexture, (GLenum target, GLuint texture), (target, texture))                     \
    X(void, glMatrixMode, (GLenum mode), (mode))                                                   \
    X(void, glLoadIdentity, (void), ())                                                            \
    X(void, glOrtho,                                                                               \
      (GLdouble left, GLdouble right, GLdouble bottom, GLdouble top, GLdouble near_val,            \
       GLdouble far_val),                                                                          \
      (left, right, bottom, top, near_val, far_val))                                               \
    X(void, glViewport, (GLint x, GLint y, GLsizei width, GLsizei height), (x, y, width, height))  \
    X(void, glScissor, (GLint x, GLint y, GLsizei width, GLsizei height), (x, y, width, height))   \
    X(void, glEnable, (GLenum cap), (cap))                                                         \
    X(void, glDisable, (GLenum cap), (cap))                                                        \
    X(void, glClearColor, (GLclampf r, GLclampf g, GLclampf b, GLclampf a), (r, g, b, a))          \
    X(void, glClear, (GLbitfield mask), (mask))                                                    \
    X(void, glGetIntegerv, (GLenum pname, GLint *data), (pname, data))                             \
    X(void, glFinish, (void), ())

/* EGL draws into a framebuffer object and reads it back (OSMesa has them
 * too, unused). */
#define CM_GL_FBO_FUNCTIONS(X)                                                                     \
    X(void, glGenFramebuffers, (GLsizei n, GLuint *ids), (n, ids))                                 \
    X(void, glDeleteFramebuffers, (GLsizei n, const GLuint *ids), (n, ids))                        \
    X(void, glBindFramebuffer, (GLenum target, GLuint id), (target, id))                           \
    X(void, glGenRenderbuffers, (GLsizei n, GLuint *ids), (n, ids))                                \
    X(void, glDeleteRenderbuffers, (GLsizei n, const GLuint *ids), (n, ids))                       \
    X(void, glBindRenderbuffer, (GLenum target, GLuint id), (target, id))                          \
    X(void, glRenderbufferStorage, (GLenum target, GLenum format, GLsizei width, GLsizei height),  \
      (target, format, width, height))                                                             \
    X(void, glFramebufferRenderbuffer,                                                             \
      (GLenum target, GLenum attachment, GLenum rb_target, GLuint rb),                             \
      (target, attachment, rb_target, rb))                                                         \
    X(void, glReadPixels,                                                                          \
      (GLint x, GLint y, GLsizei width, GLsizei height, GLenum format, GLenum type,                \
       GLvoid *pixels),                                                                            \
      (x, y, width, height, format, type, pixels))                                                \
    X(void, glClipControl, (GLenum origin, GLenum depth), (origin, depth))
#define CM_GL_FBO_VALUE_FUNCTIONS(X)                                                               \
    X(GLenum, glCheckFramebufferStatus, (GLenum target), (target))

#define CM_GL_FUNCTIONS(X)                                                                         \
    CM_GL_VALUE_FUNCTIONS(X) CM_GL_VOID_FUNCTIONS(X) CM_GL_FBO_FUNCTIONS(X)                        \
    CM_GL_FBO_VALUE_FUNCTIONS(X)

#define CM_GL_POINTER(ret, name, params, args) ret(GLAPIENTRY *name) params;
static struct {
    CM_GL_FUNCTIONS(CM_GL_POINTER)
} entry;

/* The outcome of the one load: empty when it worked, else why not. */
static char load_error[1024];
static cm_gl_backend loaded = CM_GL_NONE;
static cm_egl_api egl;
static pthread_once_t load_once = PTHREAD_ONCE_INIT;

/* The library `chosen` names, else the first of names that opens. */
static void *open_library(const char *chosen, const char *const *names, size_t n)
{
    if (chosen && chosen[0])
        return dlopen(chosen, RTLD_NOW | RTLD_LOCAL);
    for (size_t i = 0; i < n; i++) {
        void *lib = dlopen(names[i], RTLD_NOW | RTLD_LOCAL);
        if (lib)
            return lib;
    }
    return NULL;
}

typedef void (*any_function)(void);

/* POSIX lets a dlsym result be copied into a function pointer. */
static any_function symbol(void *lib, const char *name)
{
    any_function f = NULL;
    void *sym = dlsym(lib, name);
    memcpy(&f, &sym, sizeof f);
    return f;
}

/* The GL functions through the backend's GetProcAddress; OSMesa's own only
 * for OSMesa, the framebuffer ones required only by EGL. */
static void resolve_gl(any_function (*get)(const char *), cm_gl_backend backend)
{
#define CM_GL_RESOLVE(ret, name, params, args)                                                     \
    {                                                                                              \
        const bool needed = strncmp(#name, "OSMesa", 6) == 0 ? backend == CM_GL_OSMESA            \
                            : strstr(#name, "buffer") || strcmp(#name, "glReadPixels") == 0 ||    \
                                    strcmp(#name, "glClipControl") == 0                            \
                                ? backend == CM_GL_EGL                                             \
                                : true;                                                            \
        any_function p = needed ? get(#name) : NULL;                                               \
        if (!p && needed && !load_error[0])                                                        \
            snprintf(load_error, sizeof load_error, "the GL library lacks %s", #name);             \
        memcpy(&entry.name, &p, sizeof p);                                                         \
    }
    CM_GL_FUNCTIONS(CM_GL_RESOLVE)
}

static OSMESAproc (*osmesa_proc)(const char *);
static any_function osmesa_get(const char *name)
{
    any_function f = NULL;
    OSMESAproc p = osmesa_proc(name);
    memcpy(&f, &p, sizeof f);
    return f;
}

/* OSMesa: CELLMAP_OSMESA names the library, else its versioned name (the
 * one its package installs for programs), then the development link. */
static bool load_osmesa(char *why, size_t why_size)
{
    static const char *const names[] = {"libOSMesa.so.8", "libOSMesa.so"};
    void *lib = open_library(getenv("CELLMAP_OSMESA"), names, 2);
    any_function get = lib ? symbol(lib, "OSMesaGetProcAddress") : NULL;
    if (!get) {
        const char *e = dlerror();
        snprintf(why, why_size, "OSMesa: %s", e ? e : "not found");
        return false;
    }
    memcpy(&osmesa_proc, &get, sizeof get);
    resolve_gl(osmesa_get, CM_GL_OSMESA);
    return true;
}

static __eglMustCastToProperFunctionPointerType (*egl_proc)(const char *);
static any_function egl_get(const char *name)
{
    any_function f = NULL;
    __eglMustCastToProperFunctionPointerType p = egl_proc(name);
    memcpy(&f, &p, sizeof f);
    return f;
}

/* EGL (libglvnd's libEGL.so.1 with Mesa's vendor library, or the one
 * CELLMAP_EGL names): the core entry points by dlsym, the device and
 * platform extensions and GL through eglGetProcAddress. */
static bool load_egl(char *why, size_t why_size)
{
    static const char *const names[] = {"libEGL.so.1", "libEGL.so"};
    void *lib = open_library(getenv("CELLMAP_EGL"), names, 2);
    any_function get = lib ? symbol(lib, "eglGetProcAddress") : NULL;
    if (!get) {
        const char *e = dlerror();
        snprintf(why, why_size, "EGL: %s", e ? e : "not found");
        return false;
    }
    memcpy(&egl_proc, &get, sizeof get);
    any_function f;
#define CM_EGL_BIND(field, name)                                                                   \
    f = egl_get(name);                                                                             \
    memcpy(&egl.field, &f, sizeof f);                                                              \
    if (!f) {                                                                                      \
        snprintf(why, why_size, "EGL lacks %s", name);                                             \
        return false;                                                                              \
    }
    CM_EGL_BIND(QueryDevicesEXT, "eglQueryDevicesEXT")
    CM_EGL_BIND(QueryDeviceStringEXT, "eglQueryDeviceStringEXT")
    CM_EGL_BIND(GetPlatformDisplayEXT, "eglGetPlatformDisplayEXT")
    CM_EGL_BIND(Initialize, "eglInitialize")
    CM_EGL_BIND(BindAPI, "eglBindAPI")
    CM_EGL_BIND(ChooseConfig, "eglChooseConfig")
    CM_EGL_BIND(CreateContext, "eglCreateContext")
    CM_EGL_BIND(DestroyContext, "eglDestroyContext")
    CM_EGL_BIND(MakeCurrent, "eglMakeCurrent")
    CM_EGL_BIND(GetError, "eglGetError")
    resolve_gl(egl_get, CM_GL_EGL);
    return true;
}

static void load(void)
{
    const char *choice = getenv("CELLMAP_GL");
    char osmesa_why[400] = "", egl_why[400] = "";
    if (choice && choice[0] && strcmp(choice, "osmesa") != 0 && strcmp(choice, "egl") != 0) {
        snprintf(load_error, sizeof load_error,
                 "CELLMAP_GL='%.60s': use osmesa or egl (or leave it unset: OSMesa where present, "
                 "else EGL)",
                 choice);
        return;
    }
    const bool try_osmesa = !choice || !choice[0] || strcmp(choice, "osmesa") == 0;
    const bool try_egl = !choice || !choice[0] || strcmp(choice, "egl") == 0;
    if (try_osmesa && load_osmesa(osmesa_why, sizeof osmesa_why)) {
        loaded = load_error[0] ? CM_GL_NONE : CM_GL_OSMESA;
        return;
    }
    load_error[0] = 0;
    if (try_egl && load_egl(egl_why, sizeof egl_why)) {
        loaded = load_error[0] ? CM_GL_NONE : CM_GL_EGL;
        return;
    }
    snprintf(load_error, sizeof load_error,
             "cannot load a GL library to draw the image (%s%s%s): install Debian's libosmesa6, "
             "or libegl1, libegl-mesa0 and libgl1-mesa-dri; CELLMAP_OSMESA or CELLMAP_EGL name a "
             "library elsewhere",
             osmesa_why, osmesa_why[0] && egl_why[0] ? "; " : "", egl_why);
}

cm_status cm_gl_load(char *msg, size_t msg_size)
{
    pthread_once(&load_once, load);
    return load_error[0] ? cm_fail(CM_ERENDER, msg, msg_size, "%s", load_error) : CM_OK;
}

cm_gl_backend cm_gl_loaded(void) { return loaded; }

const cm_egl_api *cm_egl(void) { return &egl; }

/* The names render/ calls: each forwards to the loaded entry point. */
#define CM_GL_FORWARD_VALUE(ret, name, params, args)                                               \
    ret GLAPIENTRY name params { return entry.name args; }
#define CM_GL_FORWARD_VOID(ret, name, params, args)                                                \
    ret GLAPIENTRY name params { entry.name args; }
CM_GL_VALUE_FUNCTIONS(CM_GL_FORWARD_VALUE)
CM_GL_VOID_FUNCTIONS(CM_GL_FORWARD_VOID)
CM_GL_FBO_FUNCTIONS(CM_GL_FORWARD_VOID)
CM_GL_FBO_VALUE_FUNCTIONS(CM_GL_FORWARD_VALUE)
