/* render/palette.h - colours of basins. A group's colour follows from its
 * identity (its anchor cell on the lattice), not from its id or the other
 * groups of the file, so the same attractor has the same colour in every
 * file, view and pan; only a larger group of the same view whose anchor
 * hashes to the same colour, or a neighbouring basin too close in colour,
 * can move it (see cm_palette_classes). */
#ifndef CM_RENDER_PALETTE_H
#define CM_RENDER_PALETTE_H

#include <stdint.h>

#include "cellmap/scm.h"
#include "cellmap/status.h"
#include "render/touching.h"

typedef struct cm_rgb {
    uint8_t r, g, b;
} cm_rgb;

enum { CM_PALETTE_MAX = 64 };

/* The categorical colours of groups. */
typedef struct cm_palette {
    char name[64];
    int n;
    cm_rgb colour[CM_PALETTE_MAX];
} cm_palette;

/* Built in: "cellmap" (the default: 24 colours, the first seven Paul Tol's
 * colour-blind-safe bright and vibrant ones, the rest chosen to stay apart
 * with normal vision and, at half the distance, with deuteranopia and
 * protanopia; docs/make-palette.py), "tol" (14 colours of Tol's muted, light and
 * bright schemes), "okabe-ito" (the six of Okabe and Ito's that are neither
 * black nor close to the sink's red) and "tab20" (20 colours, not colour-
 * blind safe). No palette holds the sink's red, black, white or the greys of
 * sticking zones. */
const cm_palette *cm_palette_default(void);
/* The built-in palette `name`; CM_ENOTFOUND (msg lists the names) if none. */
cm_status cm_palette_named(const char *name, const cm_palette **out, char *msg, size_t msg_size);
/* A palette file: one colour per line as #rrggbb (blank lines and lines
 * starting with "//" ignored), 1..CM_PALETTE_MAX colours. */
cm_status cm_palette_read(const char *path, cm_palette *out, char *msg, size_t msg_size);

extern const cm_rgb cm_colour_sink;            /* transient to the sink (red, as the thesis) */
extern const cm_rgb cm_colour_not_computed;    /* cells outside every region */
extern const cm_rgb cm_colour_marker;          /* periodic cells (black dots) */
extern const cm_rgb cm_colour_sticking;        /* basins of sticking zones (grey, Fig. 4.30) */
extern const cm_rgb cm_colour_sticking_marker; /* the sticking zones' rest cells */
extern const cm_rgb cm_colour_other;           /* basins folded into "other" (--min-basin) */
/* overlays: intervals holding a chaotic repeller, and escape intervals
 * (Okabe-Ito orange and blue); switching line collisions of the first and
 * of higher orders (red and orange, as the thesis draws them) */
extern const cm_rgb cm_colour_repeller;
extern const cm_rgb cm_colour_escape;
extern const cm_rgb cm_colour_collision;
extern const cm_rgb cm_colour_collision_higher;

/* Colour differences in CIELAB (D65): cm_delta_e is ΔE*ab (CIE 1976) with
 * normal vision; cm_colour_distance is the smallest of that and twice the
 * ΔE*ab between the colours as deuteranopes and protanopes see them
 * (Machado, Oliveira and Fernandes 2009, full severity). Basins that touch
 * in a view are kept CM_NEIGHBOUR_DISTANCE apart by it: ΔE*ab >= 30 with
 * normal vision, >= 15 with either deficiency. */
#define CM_NEIGHBOUR_DISTANCE 30.0
double cm_delta_e(cm_rgb a, cm_rgb b);
double cm_colour_distance(cm_rgb a, cm_rgb b);

/* Colour classes: the figure's colours, numbered. An indexed PNG stores
 * the class of each cell; its palette is cm_class_colour of each class. */
enum cm_colour_class {
    CM_CLASS_NOT_COMPUTED = 0,
    CM_CLASS_SINK,
    CM_CLASS_MARKER,          /* periodic cells of attractors */
    CM_CLASS_STICKING,        /* basins of sticking zones */
    CM_CLASS_STICKING_MARKER, /* rest cells of sticking zones */
    CM_CLASS_OTHER,           /* groups whose basins are below --min-basin */
    CM_CLASS_FIRST_GROUP      /* then one class per categorical colour */
};
/* The classes of a palette (NULL: the default), and their colours. */
int cm_class_count(const cm_palette *p);
cm_rgb cm_class_colour(const cm_palette *p, int cls);

/* Classes of groups 1..n (entry k for group k+1) in one view. Sticking
 * zones are grey. Groups in view (in_view[k] cells; in_view NULL: all, by
 * basin) whose basins have at least min_basin cells take a palette colour,
 * largest in view first: the colour their anchor hashes to, or the next
 * one after it that no larger group of the round took and that lies
 * CM_NEIGHBOUR_DISTANCE from every coloured, sink, "other", sticking or
 * not-computed neighbour (`touching`: pairs of labels 0 = sink, group ids,
 * CM_GROUP_NONE; NULL: no neighbour rule); where no free colour is that
 * far, the free one farthest from the neighbours. So up to the palette's
 * size no two groups in view share a colour, beyond it colours repeat in
 * rounds, and a group keeps its colour in every file and view unless a
 * larger group or a close neighbour of the same view forces a change.
 * Smaller groups are CM_CLASS_OTHER. Returns how many coloured groups
 * exceed the palette (0: every colour in view is one group's). */
uint32_t cm_palette_classes(const cm_palette *p, const cm_group_info *groups, uint32_t n,
                            const cm_lattice *lat, const uint64_t *in_view, uint64_t min_basin,
                            const cm_touching *touching, uint8_t *classes);

#endif
