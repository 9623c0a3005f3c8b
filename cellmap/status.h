/* cellmap/status.h - result codes of the cellmap engine.
 *
 * Every fallible engine function returns a cm_status. CM_OK is zero; every
 * other value names a failure class. cm_strerror() gives a static, never NULL,
 * English description; functions that can say more also fill a caller buffer.
 */
#ifndef CM_STATUS_H
#define CM_STATUS_H

#include <stddef.h>

/* One table generates the enum, the names and the messages (libuv style). */
#define CM_STATUS_TABLE(X)                                                                         \
    X(CM_OK, "success")                                                                            \
    X(CM_EINVAL, "invalid argument")                                                               \
    X(CM_ENOMEM, "out of memory")                                                                  \
    X(CM_ERANGE, "value out of range")                                                             \
    X(CM_ETOOBIG, "problem too large")                                                             \
    X(CM_EMODEL, "the model aborted the computation")                                              \
    X(CM_EIO, "input/output error")                                                                \
    X(CM_EDB, "database error")                                                                    \
    X(CM_EFORMAT, "not a valid cellmap file")                                                      \
    X(CM_ERENDER, "rendering error")                                                               \
    X(CM_ENOTFOUND, "not found")                                                                   \
    X(CM_ECANCELED, "cancelled")

typedef enum cm_status {
#define CM_STATUS_ENUM(code, msg) code,
    CM_STATUS_TABLE(CM_STATUS_ENUM)
#undef CM_STATUS_ENUM
        CM_STATUS_COUNT
} cm_status;

/* Static description of a status; unknown values give "unknown status". */
const char *cm_strerror(cm_status s);
/* Symbolic name of a status, e.g. "CM_EINVAL". */
const char *cm_status_name(cm_status s);

/* Writes a printf-style message into msg (may be NULL; control characters
 * but newline and tab become '?') and returns status.
 * Lets a function report "what went wrong and how to fix it" in one line. */
cm_status cm_fail(cm_status status, char *msg, size_t msg_size, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* What a model's step (and cm_system_step) returns, SUNDIALS style: an
 * image, no image (the cell goes to the sink), or abort the run. */
enum { CM_STEP_OK = 0, CM_STEP_NO_IMAGE = 1, CM_STEP_ABORT = -1 };

#endif
