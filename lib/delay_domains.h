/* lib/delay_domains.h - the delay micro-chaos map's parameter domains
 * (thesis 4.4, App. C.3; Figs. 4.8, 4.10, C.3) over
 * models/delay_domains.h, for `cellmap stability --model
 * microchaos-delay`: the boundary curves as CSV, three charts, a report
 * and JSON of where the model's (a, b) lies, with the bands its orbit
 * visits as the independent check. Nothing is printed but to the stream
 * given; calls return a status with the problem in msg. */
#ifndef CM_LIB_DELAY_DOMAINS_H
#define CM_LIB_DELAY_DOMAINS_H

#include <stdio.h>

#include "models/params.h"
#include "lib/json.h"
#include "lib/outfile.h"
#include "models/delay_domains.h"

/* The charts' a axes: Fig. 4.8 over 1 < a < 2 (all of G), Figs. 4.10 and
 * C.3 over 1 < a < 1.45 ('01' ends at a = sqrt 2); b over 0..1. */
enum { DELAY_COLUMNS = 600 };

/* Where (a, b) lies and the bands an orbit from (0.37, 0.61) visits after
 * 2000 steps, over 20000 (0: it leaves the positive bands 0..30). */
typedef struct delay_point {
    double a, b;
    cm_delay_domains in;
    uint32_t bands;
} delay_point;

delay_point delay_point_at(double a, double b);

/* The curves per a (DELAY_COLUMNS values over 1..2) as CSV at out->csv and
 * the three charts at out->png (either NULL), the model's point marked. */
cm_status delay_domains_write(const chart_outputs *out, const char *model, const cm_params *base,
                              const delay_point *pt, char *msg, size_t msg_size);

/* The report (what the point's domains mean) and its JSON. */
void delay_domains_report(FILE *f, const delay_point *pt);
void delay_domains_json(json *j, const delay_point *pt);

#endif
