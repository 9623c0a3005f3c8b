/* cellmap/numtext.h - numbers as people read them: the shortest decimal
 * text that reads back (strtod) as the same double.
 *
 * 0.007 prints as "0.007", not "0.0070000000000000001"; a value that needs
 * all 17 significant digits gets them. Non-finite values print as "nan",
 * "inf" and "-inf". Bulk CSV columns keep printf's "%.17g", which also reads
 * back exactly and costs one conversion instead of a search. */
#ifndef CM_NUMTEXT_H
#define CM_NUMTEXT_H

#include <stddef.h>

/* Enough for any double in the shortest form, with sign and exponent. */
enum { CM_NUM_TEXT = 32 };

/* Writes the shortest round-trip text of v into buf and returns buf. */
char *cm_num_text(double v, char buf[CM_NUM_TEXT]);

/* The shortest text of a number within tol of v (tol >= 0; 0: exactly
 * v): for values known only to a resolution, such as a box's edges
 * computed from cell indices (0 + 60 * (500 / 60) is 500.00000000000006;
 * within a billionth of a cell it prints 500) or a duration. */
char *cm_num_text_near(double v, double tol, char buf[CM_NUM_TEXT]);

/* A billionth of a cell: what positions computed from cells are known to
 * (the tol of cm_num_text_near for box edges and group centres). */
#define CM_CELL_TOLERANCE 1e-9

/* cm_num_text with a buffer that lives as long as the enclosing block:
 * printf("%s", CM_NUM(x)). */
#define CM_NUM(v) cm_num_text((v), (char[CM_NUM_TEXT]){0})

/* Rewrites every JSON number in `json` in its shortest form (strings and
 * everything else copied as they are) into out. Files written before
 * numbers were printed shortest hold "0.0070000000000000001": reading them
 * through this compares equal to what is printed now. False if out is too
 * small. */
int cm_json_numbers_shortest(const char *json, char *out, size_t size);

#endif
