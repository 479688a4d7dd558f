/* CSV line helpers of the sim_host loaders (see sim_csv.h). */
#include "sim_csv.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int csv_is_eol(char c)
{
    return c == '\0' || c == '\n' || c == '\r';
}

static const char *csv_skip_blanks(const char *s)
{
    while (*s == ' ' || *s == '\t') {
        ++s;
    }
    return s;
}

int sim_csv_line_complete(const char *line, FILE *f)
{
    return strchr(line, '\n') != NULL || feof(f);
}

char *sim_csv_content(char *line)
{
    char *s = line + (csv_skip_blanks(line) - line);
    return (*s == '#' || csv_is_eol(*s)) ? NULL : s;
}

int sim_csv_is_header(const char *s, const char *header)
{
    const size_t n = strlen(header);
    return strncmp(s, header, n) == 0 && csv_is_eol(*csv_skip_blanks(s + n));
}

int sim_csv_numbers(const char *s, double *v, int n)
{
    const char *p = s;
    for (int k = 0; k < n; ++k) {
        char *end;
        errno = 0;
        v[k] = strtod(p, &end);
        if (end == p || errno != 0 || !isfinite(v[k])) {
            return -1;
        }
        p = csv_skip_blanks(end);
        if (k < n - 1) {
            if (*p != ',') {
                return -1;
            }
            ++p;
        } else if (!csv_is_eol(*p)) {
            return -1;
        }
    }
    return 0;
}
