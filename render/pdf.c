/* render/pdf.c - SVG to PDF through librsvg and cairo, loaded on demand
 * (render/pdf.h). The libraries' own headers give the types; the entry
 * points come from dlsym, as render/gl_loader.c does for GL: librsvg
 * brings GLib, Pango and cairo, 10-20 ms and tens of MiB that no command
 * should pay for a figure it does not write as PDF. */
#include "render/pdf.h"

#include <cairo-pdf.h>
#include <cairo.h>
#include <dlfcn.h>
#include <librsvg/rsvg.h>
#include <pthread.h>
#include <stdbool.h>
#include <string.h>

typedef struct pdf_api {
    RsvgHandle *(*new_from_data)(const guint8 *, gsize, GError **);
    void (*intrinsic_dimensions)(RsvgHandle *, gboolean *, RsvgLength *, gboolean *,
                                 RsvgLength *, gboolean *, RsvgRectangle *);
    gboolean (*render_document)(RsvgHandle *, cairo_t *, const RsvgRectangle *, GError **);
    void (*object_unref)(gpointer);
    void (*error_free)(GError *);
    cairo_surface_t *(*pdf_create_for_stream)(cairo_write_func_t, void *, double, double);
    void (*pdf_set_metadata)(cairo_surface_t *, cairo_pdf_metadata_t, const char *);
    cairo_t *(*create)(cairo_surface_t *);
    cairo_status_t (*status)(cairo_t *);
    void (*destroy)(cairo_t *);
    void (*surface_finish)(cairo_surface_t *);
    cairo_status_t (*surface_status)(cairo_surface_t *);
    void (*surface_destroy)(cairo_surface_t *);
    const char *(*status_to_string)(cairo_status_t);
} pdf_api;

static pthread_once_t load_once = PTHREAD_ONCE_INIT;
static pdf_api api;
static char load_error[256];

/* Binds name from lib into *slot (a function pointer of the right type:
 * POSIX guarantees the conversion from dlsym's void *). */
static bool bind_symbol(void *lib, const char *name, void *slot)
{
    void *f = lib ? dlsym(lib, name) : NULL;
    if (!f && !load_error[0])
        snprintf(load_error, sizeof load_error, "%s is missing from librsvg or cairo", name);
    memcpy(slot, &f, sizeof f);
    return f != NULL;
}

static void load(void)
{
    void *rsvg = dlopen("librsvg-2.so.2", RTLD_NOW | RTLD_LOCAL);
    void *cairo = dlopen("libcairo.so.2", RTLD_NOW | RTLD_LOCAL);
    void *gobject = dlopen("libgobject-2.0.so.0", RTLD_NOW | RTLD_LOCAL);
    void *glib = dlopen("libglib-2.0.so.0", RTLD_NOW | RTLD_LOCAL);
    if (!rsvg || !cairo || !gobject || !glib) {
        snprintf(load_error, sizeof load_error,
                 "PDF needs librsvg and cairo (Debian: apt-get install librsvg2-2 libcairo2): %s",
                 dlerror());
        return;
    }
    const struct {
        void *lib;
        const char *name;
        void *slot;
    } entries[] = {
        {rsvg, "rsvg_handle_new_from_data", &api.new_from_data},
        {rsvg, "rsvg_handle_get_intrinsic_dimensions", &api.intrinsic_dimensions},
        {rsvg, "rsvg_handle_render_document", &api.render_document},
        {gobject, "g_object_unref", &api.object_unref},
        {glib, "g_error_free", &api.error_free},
        {cairo, "cairo_pdf_surface_create_for_stream", &api.pdf_create_for_stream},
        {cairo, "cairo_pdf_surface_set_metadata", &api.pdf_set_metadata},
        {cairo, "cairo_create", &api.create},
        {cairo, "cairo_status", &api.status},
        {cairo, "cairo_destroy", &api.destroy},
        {cairo, "cairo_surface_finish", &api.surface_finish},
        {cairo, "cairo_surface_status", &api.surface_status},
        {cairo, "cairo_surface_destroy", &api.surface_destroy},
        {cairo, "cairo_status_to_string", &api.status_to_string},
    };
    bool ok = true;
    for (size_t i = 0; i < sizeof entries / sizeof entries[0]; i++)
        ok = bind_symbol(entries[i].lib, entries[i].name, entries[i].slot) && ok;
    if (ok)
        load_error[0] = '\0';
}

cm_status cm_pdf_load(char *msg, size_t msg_size)
{
    pthread_once(&load_once, load);
    if (load_error[0] || !api.new_from_data)
        return cm_fail(CM_ERENDER, msg, msg_size, "%s",
                       load_error[0] ? load_error : "PDF support did not load");
    return CM_OK;
}

static cairo_status_t write_to(void *closure, const unsigned char *data, unsigned int length)
{
    return fwrite(data, 1, length, closure) == length ? CAIRO_STATUS_SUCCESS
                                                      : CAIRO_STATUS_WRITE_ERROR;
}

/* A length of the SVG's root in points. */
static double points(const RsvgLength *l)
{
    switch (l->unit) {
    case RSVG_UNIT_PT:
        return l->length;
    case RSVG_UNIT_IN:
        return l->length * 72;
    case RSVG_UNIT_PX:
        return l->length * 72 / 96;
    default:
        return 0;
    }
}

cm_status cm_pdf_from_svg(const char *svg, size_t n, FILE *out, char *msg, size_t msg_size)
{
    cm_status st = cm_pdf_load(msg, msg_size);
    if (st != CM_OK)
        return st;
    GError *error = NULL;
    RsvgHandle *h = api.new_from_data((const guint8 *)svg, n, &error);
    if (!h) {
        st = cm_fail(CM_ERENDER, msg, msg_size, "the figure's SVG did not parse: %s",
                     error ? error->message : "no reason given");
        if (error)
            api.error_free(error);
        return st;
    }
    gboolean has_w, has_h, has_box;
    RsvgLength w, hh;
    RsvgRectangle box;
    api.intrinsic_dimensions(h, &has_w, &w, &has_h, &hh, &has_box, &box);
    const double pw = has_w ? points(&w) : 0, ph = has_h ? points(&hh) : 0;
    if (!(pw > 0 && ph > 0)) {
        api.object_unref(h);
        return cm_fail(CM_ERENDER, msg, msg_size, "the figure's SVG has no size in pt or px");
    }
    cairo_surface_t *page = api.pdf_create_for_stream(write_to, out, pw, ph);
    api.pdf_set_metadata(page, CAIRO_PDF_METADATA_CREATE_DATE, ""); /* same SVG, same bytes */
    cairo_t *cr = api.create(page);
    const RsvgRectangle viewport = {0, 0, pw, ph};
    const gboolean drawn = api.render_document(h, cr, &viewport, &error);
    const cairo_status_t cs = api.status(cr);
    api.destroy(cr);
    api.surface_finish(page);
    const cairo_status_t ps = api.surface_status(page);
    api.surface_destroy(page);
    api.object_unref(h);
    if (!drawn) {
        st = cm_fail(CM_ERENDER, msg, msg_size, "librsvg could not draw the figure: %s",
                     error ? error->message : "no reason given");
    } else if (cs != CAIRO_STATUS_SUCCESS || ps != CAIRO_STATUS_SUCCESS) {
        st = cm_fail(ps == CAIRO_STATUS_WRITE_ERROR ? CM_EIO : CM_ERENDER, msg, msg_size,
                     "cairo could not write the PDF: %s",
                     api.status_to_string(cs != CAIRO_STATUS_SUCCESS ? cs : ps));
    }
    if (error)
        api.error_free(error);
    return st;
}
