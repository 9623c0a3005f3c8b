/* render/axes.h - what figures and charts share: an RGBA canvas, filled
 * rectangles, and "nice" tick values with their labels. */
#ifndef CM_RENDER_AXES_H
#define CM_RENDER_AXES_H

#include <stdint.h>

#include "render/palette.h"
#include "render/text.h"

enum { CM_MAX_TICKS = 32 };

typedef struct cm_canvas {
    uint8_t *rgba; /* row 0 at the top */
    int w, h;
} cm_canvas;

/* Fills the rectangle, clipped to the canvas. */
void cm_fill_rect(const cm_canvas *c, int x, int y, int w, int h, cm_rgb col);

typedef struct cm_ticks {
    int n;
    double v[CM_MAX_TICKS];
    char label[CM_MAX_TICKS][32];
} cm_ticks;

/* Round values 1, 2 or 5 times a power of ten apart, about six in lo..hi. */
void cm_make_ticks(double lo, double hi, cm_ticks *t);

/* The widest label in pixels. */
int cm_ticks_widest(const cm_font *f, const cm_ticks *t);

/* The pixel (0..n) of value v on an axis of n pixels over lo..hi. */
int cm_axis_px(double v, double lo, double hi, int n);

#endif
