/* lib/figure.h - the one basin-figure pipeline: the figure of a region's
 * cells (by cell groups or by the system's attractors) as an RGB PNG with
 * its layers (axes, legend, title, overlays), as SVG, or as an indexed PNG
 * of one pixel per cell; what solve, explore, render and libcellmap draw.
 * Files are written to a temporary name and renamed when complete. Calls
 * return a status with the problem in msg; nothing is printed. A figure
 * uses one OSMesa context at a time (basin_png.gl, or one made and closed
 * per figure): not from two threads at once with the same context. */
#ifndef CM_LIB_FIGURE_H
#define CM_LIB_FIGURE_H

#include "cellmap/model.h"
#include "cellmap/scm.h"
#include "render/gl.h"
#include "render/figure.h"
#include "render/palette.h"
#include "cellmap/attractors.h"
#include "cellmap/cluster.h"
#include "cellmap/store.h"
#include "lib/work.h"

enum { PNG_LABELS_MAX = 64 };

typedef struct png_opts {
    const char *path;  /* --png FILE */
    const char *svg;   /* --svg FILE: the same figure as SVG */
    const char *pdf;   /* --pdf FILE: the same figure as PDF (that SVG drawn by render/pdf.h) */
    int width, height; /* --size WxH; 0: one pixel per cell, at most 4096 a side */
    unsigned layers;   /* --layers; 0: default_layers */
    unsigned default_layers; /* the command's default (0: basin and attractors) */
    int indexed;       /* --png-mode indexed: one pixel per cell, value = colour class */
    int has_view;      /* --view X0:X1,Y0:Y1 */
    double lo[2], hi[2];
    uint64_t min_basin; /* --min-basin N; 0: 2 in figures with a legend, else 1 */
    int legend_groups;  /* --legend K; 0: the renderer's default */
    const cm_palette *palette; /* --palette NAME|FILE; NULL: the default */
    cm_palette file_palette;   /* --palette FILE's colours */
    cm_group_label labels[PNG_LABELS_MAX]; /* --labels FILE: the legend's names */
    int n_labels;
    const char *palette_file, *labels_file; /* the files read, if any */
    int by; /* --by: BY_ATTRACTORS (the default) or BY_GROUPS (lib/attractor_report.h) */
    const char *sink_label; /* the legend's name of label 0 (NULL: "sink") */
    const char *group_noun; /* what the legend calls a group (NULL: "group") */
    const char *title;      /* --title TEXT (NULL: the model and its parameters) */
    double aspect;          /* --aspect: > 0 the ratio (1: equal), ASPECT_AUTO, or 0: equal
                               where the model declares equal axes, else auto */
    double font_size;       /* --font-size: points (png_opts_font_pixels); 0: from the size */
    double dpi;             /* --dpi: pixels per inch, written to the PNG (pHYs) and giving
                               the SVG's size in points; 0: none said */
} png_opts;

#define ASPECT_AUTO (-1.0)

/* The font's size in pixels for po: --font-size points at --dpi pixels per
 * inch (96 when not given); 0: the renderer's choice. */
double png_opts_font_pixels(const png_opts *po);

/* --aspect equal|auto|R into *aspect (png_opts.aspect); false if it is none. */
bool parse_aspect(const char *s, double *aspect);

/* What `all` draws: every layer but steps. */
extern const unsigned all_layers;

/* --palette NAME|FILE and --labels FILE into po; false with the problem
 * in msg. */
bool png_opts_palette(const char *value, png_opts *po, char *msg, size_t msg_size);
bool png_opts_labels(const char *path, png_opts *po, char *msg, size_t msg_size);

/* Refuses (false, the reason in msg) a --png or --svg that would replace
 * the database db (NULL: none; db_written: the command writes it), a
 * --palette or --labels file it read, or the other image
 * (cm_files_apart). */
/* Whether the options name a figure to write (--png, --svg or --pdf). */
bool png_opts_draws(const png_opts *po);

bool png_opts_apart(const png_opts *po, const char *db, bool db_written, char *msg,
                    size_t msg_size);

/* "basin,steps,..." or "all" -> enum cm_layer bits. On a bad word, false
 * with the word in bad. */
bool parse_layers(const char *s, unsigned *layers, char *bad, size_t bad_size);
/* "rgb" or "indexed". */
bool parse_png_mode(const char *s, int *indexed);

/* The cells a view covers: the view rectangle in dims 0 and 1, and the
 * middle cell of within in the others (a slice). */
void view_cells(const cm_lattice *lat, const double lo[2], const double hi[2], const cm_box *within,
                cm_box *out);

typedef struct basin_png {
    const png_opts *opts;
    const cm_model *model;
    const cm_lattice *lat;
    const cm_region *cells;      /* the cells to draw (group, step) */
    const cm_group_info *groups; /* the groups' summaries, for the colours */
    double lo[2], hi[2];         /* the view; all 0: the cells' box */
    cm_gl *gl;                   /* a kept GL context (render/gl.h), or NULL */
    const struct cm_attractor_set *attractors; /* not NULL: drawn by attractors (the cells'
                                                  groups' attractors, the footprints marked;
                                                  lib/attractor_report.h), else by groups */
    const struct cm_computed *computed; /* by attractors: where the sink cells' sequences go
                                           beyond the cells (NULL: not followed) */
    const int32_t *labels; /* by attractors: each cell's label found already
                              (cm_attractor_cell_labels); NULL: found here */
    cm_region *spare;      /* by attractors: `cells` itself when its owner needs
                              them no more, relabelled then in place rather than
                              in a copy; NULL: a copy */
} basin_png;

/* Checks before anything is computed that the figure of these options can
 * be drawn: for an RGB figure, its size and room for the text layers over
 * box (or the view). The outputs' paths are not checked here. */
cm_status figure_check_layout(const png_opts *po, const cm_model *m, const cm_lattice *lat,
                              const cm_box *box, char *msg, size_t msg_size);

/* figure_check_layout, and before it the --png and --svg paths
 * (lib/outfile.h: CM_EINVAL for a path the user must change). */
cm_status figure_check(const png_opts *po, const cm_model *m, const cm_lattice *lat,
                       const cm_box *box, char *msg, size_t msg_size);

/* Whether the PNG of these options draws with GL (cm_plot_needs_gl): a
 * session keeps a context only for figures that do. */
bool figure_needs_gl(const png_opts *po, const cm_model *m);

/* Whether the figure of these options shades cells by their step numbers
 * (the steps layer); otherwise a figure by attractors reads only the
 * cells' labels (cellmap/view_keep.h). */
bool figure_draws_steps(const png_opts *po);

/* Draws and writes the figure's files (the PNG at opts->path, the SVG at
 * opts->svg, either may be NULL), each reaching its path only when
 * complete. */
cm_status figure_write(const basin_png *b, char *msg, size_t msg_size);

/* The cells a figure of a file's cluster draws: po's view, else the view
 * an explore session saved in the file (note.explore.view), else the whole
 * cluster, into lo, hi (dimensions 0 and 1) and box; for models of more
 * than two dimensions the slice through slice_text ("Z,W,...", state
 * coordinates of dimensions 3..; NULL: the middle of the cluster).
 * CM_EINVAL when slice_text is not such coordinates. */
cm_status figure_file_view(cm_store *s, const cm_cluster *cl, const png_opts *po,
                           const char *slice_text, double lo[2], double hi[2], cm_box *box,
                           char *msg, size_t msg_size);

/* The figure of box's cells of a file's cluster (lib/project.h:
 * project_open_cluster; source names the file in messages): its groups
 * from the store, by attractors the ones it stores unless o asks for
 * others (found with the file's model), the cells read as hooks say
 * (cells done; a stop request ends it with CM_ECANCELED, nothing
 * written). */
cm_status figure_of_file(cm_store *s, const cm_store_info *info, cm_cluster *cl,
                         const char *source, const png_opts *po, const cm_box *box,
                         const double lo[2], const double hi[2], const cm_attractor_options *o,
                         const work_hooks *hooks, char *msg, size_t msg_size);

/* The default size of an image of the box: one pixel per cell, scaled
 * down so that neither side exceeds 4096. */
void default_image_size(const cm_lattice *lat, const cm_box *box, int *width, int *height);


/* The font for figure text: $CELLMAP_FONT, else the build's default. */
const char *figure_font(void);

#endif
