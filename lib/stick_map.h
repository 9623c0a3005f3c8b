/* lib/stick_map.h - `lyapunov --method stickmap`: the dry friction
 * oscillator's map of every k-th sticking displacement (thesis 2.6.2,
 * Fig. 2.26; models/fo_stickmap.h) and the finite-time Lyapunov exponent
 * of its chaotic transient: from random starts (the Monte Carlo diagram's
 * ranges, lib/bifurcation.h), each stick x_n and the k-th after it; while
 * an orbit has not escaped to a stable fixed point of the map (|x_n+k -
 * x_n| >= escape), ln |f'(x_n)| with f' by central differences (x_n +-
 * 1e-7, the block stuck at the same time), averaged: lambda_map per map
 * step; lambda_flow = lambda_map over the mean time of a step. Written as
 * CSV (the map's points) and as the map's graph. Nothing is printed. */
#ifndef CM_LIB_STICK_MAP_H
#define CM_LIB_STICK_MAP_H

#include <stdio.h>

#include "lib/lyapunov.h"

typedef struct stick_map_result {
    cm_params base;
    double *x, *y;       /* the map's points (x_n, x_n+k), run by run */
    unsigned char *kept; /* 1: before the orbit escaped (counted in the exponent) */
    size_t n;
    double lambda_map, lambda_flow, step_time; /* step_time: the mean time of a map step */
    size_t counted;                            /* points in the exponent */
    double seconds;
    uint64_t done; /* runs followed before a stop */
} stick_map_result;

/* a->runs runs of a->periods periods from seed a->seed, every a->every-th
 * stick, escape a->escape; on a->threads threads (0: all), progress in
 * runs through h. CM_EINVAL for another model, S > S0, or no stick to
 * count. r is freed by stick_map_free whatever the status. */
cm_status stick_map_compute(const lyap_args *a, const work_hooks *h, stick_map_result *r,
                            char *msg, size_t msg_size);
/* The points as CSV (x, x_next, counted) at a->csv, the graph at a->png. */
cm_status stick_map_write(const lyap_args *a, const stick_map_result *r, char *msg,
                          size_t msg_size);
/* The estimate as a line of text, or as JSON when a->json. */
void stick_map_report(FILE *out, const lyap_args *a, const stick_map_result *r);
void stick_map_free(stick_map_result *r);

#endif
