#include "cellmap/status.h"

#include <stdarg.h>
#include <stdio.h>

static const char *const status_messages[] = {
#define CM_STATUS_MSG(code, msg) msg,
    CM_STATUS_TABLE(CM_STATUS_MSG)
#undef CM_STATUS_MSG
};

static const char *const status_names[] = {
#define CM_STATUS_NAME(code, msg) #code,
    CM_STATUS_TABLE(CM_STATUS_NAME)
#undef CM_STATUS_NAME
};

const char *cm_strerror(cm_status s)
{
    if ((int)s < 0 || s >= CM_STATUS_COUNT)
        return "unknown status";
    return status_messages[s];
}

const char *cm_status_name(cm_status s)
{
    if ((int)s < 0 || s >= CM_STATUS_COUNT)
        return "CM_UNKNOWN";
    return status_names[s];
}

cm_status cm_fail(cm_status status, char *msg, size_t msg_size, const char *fmt, ...)
{
    if (msg && msg_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, msg_size, fmt, ap);
        va_end(ap);
        /* messages quote what files and arguments hold: control characters
         * (a terminal's escape sequences) are shown as '?' */
        for (char *p = msg; *p; p++)
            if ((unsigned char)*p < 0x20 ? *p != '\n' && *p != '\t' : *p == 0x7f)
                *p = '?';
    }
    return status;
}
