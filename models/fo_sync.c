#include "models/fo_sync.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

/* The coupled pair between events: y = (x1, v1, x3, v3), each block
 * sliding up (+1), down (-1) or at rest (0). A block at rest keeps v = 0;
 * the copy's position still follows the coupling. */
typedef struct pair {
    const cm_fo_sync *c;
    double q;
    int mode[2];
} pair;

static double forcing(const pair *p, double t) { return cos(p->c->Omega * t); }

/* The net force on a block but friction. */
static double net_force(const pair *p, const double *y, int block, double t)
{
    return block == 0 ? -y[0] + forcing(p, t) : -y[2] + forcing(p, t) + p->q * (y[1] - y[3]);
}

static void rates(const pair *p, double t, const double *y, double *dy)
{
    dy[0] = y[1];
    dy[2] = y[3] + p->q * (y[0] - y[2]);
    for (int b = 0; b < 2; b++)
        dy[2 * b + 1] = p->mode[b] ? net_force(p, y, b, t) - p->c->S * p->mode[b] : 0;
}

static void rk4(const pair *p, double t, const double *y, double h, double *out)
{
    double k1[4], k2[4], k3[4], k4[4], z[4];
    rates(p, t, y, k1);
    for (int i = 0; i < 4; i++)
        z[i] = y[i] + h / 2 * k1[i];
    rates(p, t + h / 2, z, k2);
    for (int i = 0; i < 4; i++)
        z[i] = y[i] + h / 2 * k2[i];
    rates(p, t + h / 2, z, k3);
    for (int i = 0; i < 4; i++)
        z[i] = y[i] + h * k3[i];
    rates(p, t + h, z, k4);
    for (int i = 0; i < 4; i++)
        out[i] = y[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
}

/* Positive while block b stays in its mode: a sliding block's velocity in
 * its direction, a resting block's margin of static friction. */
static double margin(const pair *p, const double *y, int b, double t)
{
    return p->mode[b] ? y[2 * b + 1] * p->mode[b] : p->c->S0 - fabs(net_force(p, y, b, t));
}

/* The mode after block b's event at (t, y): at a velocity zero it rests
 * if static friction holds it, else slides along the net force; a
 * resting block slides off along it. */
static int next_mode(const pair *p, const double *y, int b, double t)
{
    const double f = net_force(p, y, b, t);
    if (p->mode[b] && fabs(f) <= p->c->S0)
        return 0;
    return f > 0 ? 1 : -1;
}

/* Advances (t, y) by h, stopping at events: each is located by bisection
 * on the step to 1e-13 and the blocks whose margins end there switch. */
static void advance(pair *p, double t, double *y, double h)
{
    const double end = t + h;
    while (end - t > 1e-15) {
        double trial[4];
        const double step = end - t;
        rk4(p, t, y, step, trial);
        bool event = false;
        for (int b = 0; b < 2; b++)
            event = event || margin(p, trial, b, t + step) < 0;
        if (!event) {
            memcpy(y, trial, sizeof trial);
            return;
        }
        double lo = 0, hi = step; /* no event by lo, one by hi */
        while (hi - lo > 1e-13) {
            const double mid = (lo + hi) / 2;
            rk4(p, t, y, mid, trial);
            bool any = false;
            for (int b = 0; b < 2; b++)
                any = any || margin(p, trial, b, t + mid) < 0;
            if (any)
                hi = mid;
            else
                lo = mid;
        }
        rk4(p, t, y, hi, trial);
        t += hi;
        memcpy(y, trial, sizeof trial);
        int mode[2] = {p->mode[0], p->mode[1]};
        for (int b = 0; b < 2; b++)
            if (margin(p, y, b, t) < 0) {
                if (p->mode[b])
                    y[2 * b + 1] = 0; /* at the velocity zero */
                mode[b] = next_mode(p, y, b, t);
            }
        memcpy(p->mode, mode, sizeof mode);
    }
}

static int mode_at(const cm_fo_sync *c, double v, double f)
{
    if (v != 0)
        return v > 0 ? 1 : -1;
    return fabs(f) <= c->S0 ? 0 : f > 0 ? 1 : -1;
}

double cm_fo_sync_run(const cm_fo_sync *c, double q, double *gaps)
{
    const double h = 6.283185307179586 / c->Omega / c->steps;
    pair p = {c, q, {0, 0}};
    double y[4] = {c->start[0], c->start[1], c->start[0] + c->copy_offset[0],
                   c->start[1] + c->copy_offset[1]};
    p.mode[0] = mode_at(c, y[1], net_force(&p, y, 0, 0));
    p.mode[1] = mode_at(c, y[3], net_force(&p, y, 1, 0));
    double largest = 0;
    for (int period = 0; period < c->transient + c->record; period++) {
        const bool watched = period >= c->transient;
        for (int k = 0; k < c->steps; k++) {
            /* the time from the step count: no drift over thousands of periods */
            advance(&p, h * ((double)period * c->steps + k), y, h);
            if (watched) {
                const double d = fmax(fabs(y[0] - y[2]), fabs(y[1] - y[3]));
                largest = d > largest ? d : largest;
            }
        }
        if (watched && gaps)
            gaps[period - c->transient] = y[0] - y[2];
    }
    return largest;
}
