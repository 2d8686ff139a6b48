/* The parameter checks' message helpers (see messages.h). */
#include "messages.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void ml_repr_double(double x, char *buf, size_t size)
{
    char tmp[40], digits[24];
    int prec, exp10, nd = 0, i;
    const char *s;
    char *out = buf;
    size_t room = size;
    if (isnan(x)) {
        snprintf(buf, size, "nan");
        return;
    }
    if (isinf(x)) {
        snprintf(buf, size, x < 0 ? "-inf" : "inf");
        return;
    }
    for (prec = 1; prec <= 17; ++prec) {
        snprintf(tmp, sizeof tmp, "%.*e", prec - 1, x);
        if (strtod(tmp, NULL) == x)
            break;
    }
    s = tmp;
    if (*s == '-') {
        if (room > 1) {
            *out++ = '-';
            --room;
        }
        ++s;
    }
    for (; *s && *s != 'e'; ++s)
        if (*s != '.' && nd < (int)sizeof digits - 1)
            digits[nd++] = *s;
    exp10 = *s == 'e' ? atoi(s + 1) : 0;
    while (nd > 1 && digits[nd - 1] == '0')
        --nd;
    digits[nd] = '\0';
    if (exp10 < -4 || exp10 >= 16) {
        snprintf(out, room, "%c%s%s%se%c%02d", digits[0], nd > 1 ? "." : "",
                 digits + 1, "", exp10 < 0 ? '-' : '+', abs(exp10));
        return;
    }
    if (exp10 < 0) {
        char zeros[8] = "";
        for (i = 0; i < -exp10 - 1; ++i)
            zeros[i] = '0';
        zeros[-exp10 - 1] = '\0';
        snprintf(out, room, "0.%s%s", zeros, digits);
        return;
    }
    {
        char intpart[24], frac[24], text[64];
        size_t len;
        for (i = 0; i <= exp10; ++i)
            intpart[i] = i < nd ? digits[i] : '0';
        intpart[exp10 + 1] = '\0';
        if (nd > exp10 + 1)
            snprintf(frac, sizeof frac, "%s", digits + exp10 + 1);
        else
            snprintf(frac, sizeof frac, "0");
        /* composed here, then cut to room (snprintf straight into out draws a
         * -Wformat-truncation warning once inlined into the one translation unit) */
        snprintf(text, sizeof text, "%s.%s", intpart, frac);
        len = strlen(text);
        if (room == 0)
            return;
        len = len < room ? len : room - 1;
        memcpy(out, text, len);
        out[len] = '\0';
    }
}

void ml_append_problem(char *buf, size_t size, int *count, const char *text)
{
    size_t len = strlen(buf);
    if (len + 1 >= size)
        return;
    snprintf(buf + len, size - len, "%s%s", *count ? "; " : "", text);
    ++*count;
}

