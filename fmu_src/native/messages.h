/* Message helpers of the parameter checks (Python's texts, character for character):
 * used by mount_law.c, jenkins.c, inclined.c and inclined_element.c. */
#ifndef DRYMOUNT_MESSAGES_H
#define DRYMOUNT_MESSAGES_H

#include "internal.h"

#ifdef __cplusplus
extern "C" {
#endif

#include <stddef.h>

/* Python's repr() of a float (shortest round-trip text), for the messages. */
ML_DECL void ml_repr_double(double x, char *buf, size_t size);

/* Append "; " (unless *count is 0) and text to buf (NUL-terminated, truncated if too
 * small) and count it: the "; "-separated problem lists of the parameter checks. */
ML_DECL void ml_append_problem(char *buf, size_t size, int *count, const char *text);

#ifdef __cplusplus
}
#endif

#endif
