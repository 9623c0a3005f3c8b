#include "render/axes.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>

void cm_fill_rect(const cm_canvas *c, int x, int y, int w, int h, cm_rgb col)
{
    for (int j = y < 0 ? 0 : y; j < y + h && j < c->h; j++)
        for (int i = x < 0 ? 0 : x; i < x + w && i < c->w; i++) {
            uint8_t *p = c->rgba + 4 * ((size_t)j * (size_t)c->w + (size_t)i);
            p[0] = col.r;
            p[1] = col.g;
            p[2] = col.b;
            p[3] = 255;
        }
}

/* Round values 1, 2 or 5 times a power of ten apart, about six in range. */
void cm_make_ticks(double lo, double hi, cm_ticks *t)
{
    t->n = 0;
    const double raw = (hi - lo) / 6;
    if (!(raw > 0) || !isfinite(raw))
        return;
    const double mag = pow(10, floor(log10(raw)));
    const double step = raw <= mag       ? mag
                        : raw <= 2 * mag ? 2 * mag
                        : raw <= 5 * mag ? 5 * mag
                                         : 10 * mag;
    const double biggest = fmax(fabs(lo), fabs(hi));
    const bool fixed = biggest < 1e7 && step >= 1e-4;
    const int decimals = step >= 1 ? 0 : (int)ceil(-log10(step) - 1e-9);
    const double wanted = ceil(log10(biggest / step) + 1e-9); /* digits above the step's */
    const int precision = wanted < 0 ? 0 : wanted > 16 ? 16 : (int)wanted;
    /* Whole multiples of step in lo..hi, the ends included although lo / step
     * may round to just above an integer and k * step to just above hi
     * (-0.3 / 0.1 = -2.9999999999999996, 3 * 0.1 = 0.30000000000000004). */
    const double slack = 1e-9;
    const double k_last = floor(hi / step + slack);
    for (double k = ceil(lo / step - slack); k <= k_last && t->n < CM_MAX_TICKS; k++) {
        const double v = k == 0 ? 0.0 : k * step;
        t->v[t->n] = v;
        if (fixed)
            snprintf(t->label[t->n], sizeof t->label[0], "%.*f", decimals, v);
        else
            snprintf(t->label[t->n], sizeof t->label[0], "%.*e", precision, v);
        t->n++;
    }
}

int cm_ticks_widest(const cm_font *f, const cm_ticks *t)
{
    int w = 0;
    for (int k = 0; k < t->n; k++) {
        const int lw = cm_font_width(f, t->label[k]);
        w = lw > w ? lw : w;
    }
    return w;
}

int cm_axis_px(double v, double lo, double hi, int n)
{
    return (int)floor((v - lo) / (hi - lo) * n);
}
