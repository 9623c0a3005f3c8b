/* lib/serve_page.h - the HTML page of `cellmap serve` (lib/serve_page.c):
 * its parts in order, NULL after the last. */
#ifndef CM_LIB_SERVE_PAGE_H
#define CM_LIB_SERVE_PAGE_H

extern const char *const serve_page[];

#endif
