/* lib/parse.h - the text forms users give numbers, sizes, ranges and
 * counts in: the command's options, the library's calls and the notes a
 * .cmdb keeps all read them here, so that they read alike. Each returns
 * false on malformed input and then leaves its outputs unspecified. */
#ifndef CM_LIB_PARSE_H
#define CM_LIB_PARSE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* A whole number in int64_t's range, nothing before or after it. */
bool parse_int64(const char *s, int64_t *out);
/* A finite double, nothing before or after it. */
bool parse_double(const char *s, double *out);
/* A size in bytes: digits with an optional K, M or G (powers of 1024). */
bool parse_bytes(const char *s, uint64_t *out);
/* "LO:HI,LO:HI,..." (LO < HI each) -> lo[], hi[], *count (at most max). */
bool parse_ranges(const char *s, double *lo, double *hi, int *count, int max);
/* "NxMx..." with positive counts -> n[], *count (at most max). */
bool parse_counts(const char *s, int64_t *n, int *count, int max);
/* "N" or "N:M" (whole numbers, N <= M) -> lo, hi (N alone: both). */
bool parse_int_span(const char *s, int *lo, int *hi);
/* "X,Y,..." -> v[], *count (at most max). */
bool parse_doubles(const char *s, double *v, int *count, int max);
/* Splits a line in place into at most max words (tokens[]; "double
 * quotes" keep spaces), dropping a # comment: their count, or -1 with the
 * problem in msg. */
int parse_words(char *line, char **tokens, int max, char *msg, size_t msg_size);

#endif
