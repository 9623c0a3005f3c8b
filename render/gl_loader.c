/* render/gl_loader.c - OSMesa and the GL functions render/ calls, loaded
 * when the first context is made (cm_gl_load), so that commands which draw
 * nothing never map OSMesa and the LLVM it brings (about 50 MiB and 20 ms
 * at every start).
 *
 * Each function the renderer calls is defined here under its own name and
 * forwards to the library's entry point, so the drawing code reads as
 * plain GL. The table of entry points is filled once per process, like the
 * dynamic linker's own bindings, and never changes afterwards.
 */
#include "render/gl_loader.h"

#include <GL/osmesa.h>
#include <dlfcn.h>
#include <pthread.h>
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
    X(void, glFinish, (void), ())

#define CM_GL_FUNCTIONS(X) CM_GL_VALUE_FUNCTIONS(X) CM_GL_VOID_FUNCTIONS(X)

#define CM_GL_POINTER(ret, name, params, args) ret(GLAPIENTRY *name) params;
static struct {
    CM_GL_FUNCTIONS(CM_GL_POINTER)
} entry;

/* The outcome of the one load: empty when it worked, else why not. */
static char load_error[512];
static pthread_once_t load_once = PTHREAD_ONCE_INIT;

/* The library CELLMAP_OSMESA names, else under its versioned name (the
 * one its package installs for programs), then the development link. */
static void *open_osmesa(void)
{
    const char *chosen = getenv("CELLMAP_OSMESA");
    if (chosen && chosen[0])
        return dlopen(chosen, RTLD_NOW | RTLD_LOCAL);
    static const char *const names[] = {"libOSMesa.so.8", "libOSMesa.so"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        void *lib = dlopen(names[i], RTLD_NOW | RTLD_LOCAL);
        if (lib)
            return lib;
    }
    return NULL;
}

static void load(void)
{
    void *lib = open_osmesa();
    if (!lib) {
        const char *why = dlerror();
        snprintf(load_error, sizeof load_error,
                 "cannot load OSMesa to draw the image (%s): install Debian's libosmesa6, or "
                 "name the library in CELLMAP_OSMESA",
                 why ? why : "not found");
        return;
    }
    /* POSIX lets a dlsym result be copied into a function pointer */
    OSMESAproc (*get_proc)(const char *) = NULL;
    void *sym = dlsym(lib, "OSMesaGetProcAddress");
    memcpy(&get_proc, &sym, sizeof get_proc);
    if (!get_proc) {
        snprintf(load_error, sizeof load_error, "OSMesa has no OSMesaGetProcAddress: %s",
                 dlerror());
        return;
    }
#define CM_GL_RESOLVE(ret, name, params, args)                                                     \
    {                                                                                              \
        OSMESAproc p = get_proc(#name);                                                            \
        if (!p && !load_error[0])                                                                  \
            snprintf(load_error, sizeof load_error, "OSMesa lacks %s", #name);                     \
        memcpy(&entry.name, &p, sizeof p);                                                         \
    }
    CM_GL_FUNCTIONS(CM_GL_RESOLVE)
}

cm_status cm_gl_load(char *msg, size_t msg_size)
{
    pthread_once(&load_once, load);
    return load_error[0] ? cm_fail(CM_ERENDER, msg, msg_size, "%s", load_error) : CM_OK;
}

/* The names render/ calls: each forwards to the loaded entry point. */
#define CM_GL_FORWARD_VALUE(ret, name, params, args)                                               \
    ret GLAPIENTRY name params { return entry.name args; }
#define CM_GL_FORWARD_VOID(ret, name, params, args)                                                \
    ret GLAPIENTRY name params { entry.name args; }
CM_GL_VALUE_FUNCTIONS(CM_GL_FORWARD_VALUE)
CM_GL_VOID_FUNCTIONS(CM_GL_FORWARD_VOID)
