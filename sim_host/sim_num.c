#include "sim_num.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

int sim_num_parse(const char *s, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(s, &end);
    if (end == s || *end != '\0' || errno != 0 || !isfinite(v)) {
        return -1;
    }
    *out = v;
    return 0;
}
