#include "render/gl.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl_loader.h"

struct cm_gl {
    cm_gl_backend backend;
    OSMesaContext osmesa;
    EGLDisplay display;
    EGLContext context;
    GLuint fbo, colour;          /* EGL: the framebuffer drawn into */
    int fb_w, fb_h;              /* its size */
    uint8_t *target;             /* the tile's first pixel in the caller's image */
    int row_pixels, w, h;        /* the tile */
};

/* Mesa's software device (llvmpipe), so that a machine with a GPU draws
 * the same bytes as one without; else the surfaceless platform, which
 * falls back to software where there is no GPU. */
static EGLDisplay software_display(const cm_egl_api *e)
{
    EGLDeviceEXT devices[16];
    EGLint n = 0;
    if (e->QueryDevicesEXT(16, devices, &n))
        for (EGLint k = 0; k < n; k++) {
            const char *ext = e->QueryDeviceStringEXT(devices[k], EGL_EXTENSIONS);
            if (ext && strstr(ext, "EGL_MESA_device_software"))
                return e->GetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[k], NULL);
        }
    return e->GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
}

static cm_status open_egl(cm_gl *gl, char *msg, size_t msg_size)
{
    const cm_egl_api *e = cm_egl();
    gl->display = software_display(e);
    EGLint major, minor;
    if (gl->display == EGL_NO_DISPLAY || !e->Initialize(gl->display, &major, &minor))
        return cm_fail(CM_ERENDER, msg, msg_size,
                       "EGL has no software display (error 0x%x): install Debian's "
                       "libegl-mesa0 and libgl1-mesa-dri",
                       (unsigned)e->GetError());
    const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = EGL_NO_CONFIG_KHR;
    EGLint count = 0;
    if (!e->ChooseConfig(gl->display, want, &config, 1, &count) || count < 1)
        config = EGL_NO_CONFIG_KHR; /* a context without one draws into framebuffers */
    if (!e->BindAPI(EGL_OPENGL_API) ||
        (gl->context = e->CreateContext(gl->display, config, EGL_NO_CONTEXT, NULL)) ==
            EGL_NO_CONTEXT ||
        !e->MakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->context))
        return cm_fail(CM_ERENDER, msg, msg_size,
                       "cannot create an EGL context for desktop OpenGL (error 0x%x)",
                       (unsigned)e->GetError());
    return CM_OK;
}

cm_status cm_gl_open(cm_gl **out, char *msg, size_t msg_size)
{
    *out = NULL;
    cm_status st = cm_gl_load(msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_gl *gl = calloc(1, sizeof *gl);
    if (!gl)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a GL context");
    gl->backend = cm_gl_loaded();
    if (gl->backend == CM_GL_EGL) {
        st = open_egl(gl, msg, msg_size);
    } else {
        gl->osmesa = OSMesaCreateContextExt(OSMESA_RGBA, 0, 0, 0, NULL);
        if (!gl->osmesa)
            st = cm_fail(CM_ERENDER, msg, msg_size, "cannot create an OSMesa context");
    }
    if (st != CM_OK) {
        cm_gl_close(gl);
        return st;
    }
    *out = gl;
    return CM_OK;
}

void cm_gl_close(cm_gl *gl)
{
    if (!gl)
        return;
    if (gl->backend == CM_GL_EGL && gl->context != EGL_NO_CONTEXT && gl->context) {
        const cm_egl_api *e = cm_egl();
        if (e->MakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->context)) {
            glDeleteFramebuffers(1, &gl->fbo);
            glDeleteRenderbuffers(1, &gl->colour);
        }
        e->MakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        e->DestroyContext(gl->display, gl->context);
    }
    if (gl->osmesa)
        OSMesaDestroyContext(gl->osmesa);
    free(gl);
}

const char *cm_gl_backend_name(const cm_gl *gl)
{
    return gl->backend == CM_GL_EGL ? "EGL" : "OSMesa";
}

/* EGL: a framebuffer of at least w x h, current. */
static cm_status egl_framebuffer(cm_gl *gl, int w, int h, char *msg, size_t msg_size)
{
    const cm_egl_api *e = cm_egl();
    if (!e->MakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->context))
        return cm_fail(CM_ERENDER, msg, msg_size, "eglMakeCurrent failed (error 0x%x)",
                       (unsigned)e->GetError());
    if (w > gl->fb_w || h > gl->fb_h) {
        const int fw = w > gl->fb_w ? w : gl->fb_w, fh = h > gl->fb_h ? h : gl->fb_h;
        if (!gl->fbo) {
            glGenFramebuffers(1, &gl->fbo);
            glGenRenderbuffers(1, &gl->colour);
        }
        glBindRenderbuffer(GL_RENDERBUFFER, gl->colour);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, fw, fh);
        glBindFramebuffer(GL_FRAMEBUFFER, gl->fbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                  gl->colour);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            return cm_fail(CM_ERENDER, msg, msg_size, "no %dx%d framebuffer for EGL", fw, fh);
        gl->fb_w = fw, gl->fb_h = fh;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, gl->fbo);
    /* rows top down, as Mesa renders OSMesa's buffer: the same rasterisation */
    glClipControl(GL_UPPER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    return CM_OK;
}

cm_status cm_gl_target(cm_gl *gl, uint8_t *origin, int row_pixels, int w, int h, char *msg,
                       size_t msg_size)
{
    gl->target = origin;
    gl->row_pixels = row_pixels;
    gl->w = w, gl->h = h;
    if (gl->backend == CM_GL_EGL)
        return egl_framebuffer(gl, w, h, msg, msg_size);
    if (!OSMesaMakeCurrent(gl->osmesa, origin, GL_UNSIGNED_BYTE, w, h))
        return cm_fail(CM_ERENDER, msg, msg_size, "OSMesaMakeCurrent failed for a %dx%d tile", w,
                       h);
    OSMesaPixelStore(OSMESA_ROW_LENGTH, row_pixels);
    OSMesaPixelStore(OSMESA_Y_UP, 0); /* row 0 at the top, as PNG wants */
    return CM_OK;
}

/* EGL's framebuffer counts rows from the top (glClipControl), GL's window
 * (OSMesa) from the bottom: the row GL knows r's bottom by. */
static int window_y(const cm_gl *gl, const cm_gl_rect *r)
{
    return gl->backend == CM_GL_EGL ? r->y_top : gl->h - r->y_top - r->h;
}

void cm_gl_window(const cm_gl *gl, const cm_gl_rect *view, const cm_gl_rect *scissor)
{
    glViewport(view->x, window_y(gl, view), view->w, view->h);
    glScissor(scissor->x, window_y(gl, scissor), scissor->w, scissor->h);
}

cm_status cm_gl_done(cm_gl *gl, char *msg, size_t msg_size)
{
    glFinish(); /* OSMesa's buffer is complete only now */
    if (glGetError() != GL_NO_ERROR)
        return cm_fail(CM_ERENDER, msg, msg_size, "OpenGL reported an error while drawing");
    if (gl->backend != CM_GL_EGL)
        return CM_OK;
    /* straight into the image: the framebuffer's row 0 is the top too */
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, gl->row_pixels);
    glReadPixels(0, 0, gl->w, gl->h, GL_RGBA, GL_UNSIGNED_BYTE, gl->target);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    if (glGetError() != GL_NO_ERROR)
        return cm_fail(CM_ERENDER, msg, msg_size, "OpenGL could not read the tile back");
    return CM_OK;
}
