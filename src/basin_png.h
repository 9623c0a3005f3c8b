/* src/basin_png.h - the basin PNG that solve, explore and render write, and
 * the options they share: --png, --size, --layers, --png-mode, --view. */
#ifndef CM_SRC_BASIN_PNG_H
#define CM_SRC_BASIN_PNG_H

#include "cellmap/model.h"
#include "cellmap/scm.h"
#include "render/gl.h"
#include "render/figure.h"
#include "render/palette.h"
#include "src/args.h"

enum { PNG_LABELS_MAX = 64 };

typedef struct png_opts {
    const char *path;  /* --png FILE */
    const char *svg;   /* --svg FILE: the same figure as SVG */
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
    int by; /* --by: BY_ATTRACTORS (the default) or BY_GROUPS (src/attractor_report.h) */
    const char *sink_label; /* the legend's name of label 0 (NULL: "sink") */
} png_opts;

/* What `all` draws: every layer but steps. */
extern const unsigned all_layers;

#define PNG_OPTIONS_HELP                                                                           \
    "  --size WxH          image size in pixels (default: one pixel per cell, at most 4096;\n"     \
    "                      1000 on the longer side for figures with text)\n"                       \
    "  --layers L,...      what to draw: basin, steps (shading by transient length; alone:\n"      \
    "                      step numbers only), attractors, overlays (switching lines, fixed\n"     \
    "                      points, manifolds, sticking zones, repellers orange and escape\n"      \
    "                      intervals blue), axes, legend, title; or all\n"                          \
    "                      (default: basin,attractors)\n"                                          \
    "  --png-mode MODE     rgb (a figure) or indexed (one pixel per cell, its value the\n"         \
    "                      colour class; the classes of groups are in the PNG's texts)\n"          \
    "  --view X0:X1,Y0:Y1  the rectangle of state space to draw (default: all cells;\n"            \
    "                      1-D models ignore Y0:Y1)\n"                                             \
    "  --svg FILE          the same figure as SVG: text and paths, with the basins\n"           \
    "                      embedded as a PNG of one pixel per cell\n"                             \
    "  --min-basin N       draw groups whose basins have fewer than N cells as 'other' (one\n"   \
    "                      muted colour, one legend line); default 2 in figures with a\n"         \
    "                      legend (single-cell groups folded), else 1 (none)\n"                    \
    "  --palette P         group colours: tol (default; colour-blind safe), okabe-ito,\n"     \
    "                      tab20, or a file of #rrggbb lines\n"                                     \
    "  --labels FILE       the legend's names of groups: lines 'ID TEXT' or, for the same\n"   \
    "                      attractor in any file, 'ANCHOR TEXT' with the anchor cell's\n"      \
    "                      indices as export --groups lists them (e.g. 287,500 SW2)\n"        \
    "  --legend K          list at most K groups in the legend (default 12), the rest in one\n"   \
    "                      line; colours follow each attractor's anchor cell, so the same\n"     \
    "                      attractor has the same colour in every file and view\n"

/* --palette NAME|FILE and --labels FILE into po; false with the problem
 * in msg. */
bool png_opts_palette(const char *value, png_opts *po, char *msg, size_t msg_size);
bool png_opts_labels(const char *path, png_opts *po, char *msg, size_t msg_size);

/* Handles the shared options; true if the current option was one of them. */
bool png_opts_take(cli *c, png_opts *po, int *error);
/* Checks the options together (e.g. indexed images take no --size). */
int png_opts_check(const cli *c, const png_opts *po);

/* Refuses (false, the reason in msg) a --png or --svg that would replace
 * the database db (NULL: none; db_written: the command writes it), a
 * --palette or --labels file it read, or the other image
 * (cm_files_apart). */
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
    cm_gl *gl;                   /* a kept OSMesa context, or NULL */
    const struct cm_attractor_set *attractors; /* not NULL: drawn by attractors (the cells'
                                                  groups' attractors, the footprints marked;
                                                  src/attractor_report.h), else by groups */
    const struct cm_computed *computed; /* by attractors: where the sink cells' sequences go
                                           beyond the cells (NULL: not followed) */
} basin_png;

/* Checks before anything is computed that the PNG of these options can be
 * written: its path (cellmap/output.h) and, for a figure, its size and
 * room for the text layers over box (or the --view). Prints "cellmap CMD:
 * problem" and returns EXIT_FAIL if not. */
int check_basin_png(const char *cmd, const png_opts *po, const cm_model *m,
                    const cm_lattice *lat, const cm_box *box);

/* Renders and writes the PNG (temporary file, then rename). Prints
 * "cellmap CMD: problem" and returns EXIT_FAIL on failure. */
int write_basin_png(const char *cmd, const basin_png *b);

/* The default size of an image of the box: one pixel per cell, scaled
 * down so that neither side exceeds 4096. */
void default_image_size(const cm_lattice *lat, const cm_box *box, int *width, int *height);


/* The font for figure text: $CELLMAP_FONT, else the build's default. */
const char *figure_font(void);

#endif
