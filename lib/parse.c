/* lib/parse.c - the text forms users give numbers, sizes, ranges and
 * counts in, shared by the command's options, the library's calls and the
 * notes a .cmdb keeps. */
#include "lib/parse.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/status.h"

bool parse_int64(const char *s, int64_t *out)
{
    char *end = NULL;
    errno = 0;
    const long long v = strtoll(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE)
        return false;
    *out = v;
    return true;
}

bool parse_bytes(const char *s, uint64_t *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long long v = strtoull(s, &end, 10);
    if (end == s || *s == '-' || errno == ERANGE)
        return false;
    const char units[] = "KMG";
    const char *u = *end ? strchr(units, *end) : NULL;
    if (*end && (!u || end[1] != '\0'))
        return false;
    const int shift = u ? 10 * (int)(u - units + 1) : 0;
    if (v > (UINT64_MAX >> shift))
        return false;
    *out = (uint64_t)v << shift;
    return true;
}

bool parse_double(const char *s, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(s, &end);
    if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v))
        return false;
    *out = v;
    return true;
}

/* Copies the piece of s up to sep (or the end) into piece, at most 255
 * characters; returns where the next piece starts, s's end if this was
 * the last, or NULL for an empty or too long piece. */
static const char *take_piece(const char *s, char sep, char piece[256])
{
    const char *end = strchr(s, sep);
    const size_t len = end ? (size_t)(end - s) : strlen(s);
    if (len == 0 || len >= 256)
        return NULL;
    memcpy(piece, s, len);
    piece[len] = '\0';
    return end ? end + 1 : s + len;
}

/* Calls parse_one on each piece of s between seps, at most max pieces; the
 * count, or -1 if a piece is malformed, empty or one too many. */
static int parse_pieces(const char *s, char sep, int max, void *out,
                        bool (*parse_one)(char *piece, void *out, int index))
{
    char piece[256];
    int n = 0;
    for (const char *p = s; p && *p; n++) {
        if (n == max || !(p = take_piece(p, sep, piece)) || !parse_one(piece, out, n))
            return -1;
        if (p[-1] == sep && *p == '\0')
            return -1; /* a trailing separator */
    }
    return n > 0 ? n : -1;
}

typedef struct ranges_out {
    double *lo, *hi;
} ranges_out;

static bool parse_range(char *piece, void *out, int d)
{
    ranges_out *r = out;
    char *colon = strchr(piece, ':');
    if (!colon)
        return false;
    *colon = '\0';
    return parse_double(piece, &r->lo[d]) && parse_double(colon + 1, &r->hi[d]) &&
           r->lo[d] < r->hi[d];
}

static bool parse_count(char *piece, void *out, int d)
{
    int64_t *v = out;
    return parse_int64(piece, &v[d]) && v[d] >= 1;
}

static bool parse_one_double(char *piece, void *out, int d)
{
    return parse_double(piece, (double *)out + d);
}

bool parse_ranges(const char *s, double *lo, double *hi, int *count, int max)
{
    ranges_out r = {lo, hi};
    const int n = parse_pieces(s, ',', max, &r, parse_range);
    if (n > 0)
        *count = n;
    return n > 0;
}

bool parse_counts(const char *s, int64_t *v, int *count, int max)
{
    const int n = parse_pieces(s, 'x', max, v, parse_count);
    if (n > 0)
        *count = n;
    return n > 0;
}

bool parse_int_span(const char *s, int *lo, int *hi)
{
    char first[32];
    const char *colon = strchr(s, ':');
    const size_t len = colon ? (size_t)(colon - s) : strlen(s);
    int64_t a, b;
    if (len >= sizeof first)
        return false;
    memcpy(first, s, len);
    first[len] = 0;
    if (!parse_int64(first, &a) || !parse_int64(colon ? colon + 1 : first, &b) || a > b ||
        a < INT32_MIN || b > INT32_MAX)
        return false;
    *lo = (int)a, *hi = (int)b;
    return true;
}

bool parse_doubles(const char *s, double *v, int *count, int max)
{
    const int n = parse_pieces(s, ',', max, v, parse_one_double);
    if (n > 0)
        *count = n;
    return n > 0;
}

int parse_words(char *line, char **tokens, int max, char *msg, size_t msg_size)
{
    int n = 0;
    char *p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
            p++;
        if (!*p || *p == '#')
            return n;
        if (n == max) {
            cm_fail(CM_EINVAL, msg, msg_size, "too many words (at most %d)", max);
            return -1;
        }
        if (*p == '"') {
            tokens[n++] = ++p;
            while (*p && *p != '"')
                p++;
            if (!*p) {
                cm_fail(CM_EINVAL, msg, msg_size, "a \" is not closed");
                return -1;
            }
        } else {
            tokens[n++] = p;
            while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n')
                p++;
        }
        if (*p)
            *p++ = 0;
    }
}
