/* Unity output port for hosted builds: characters to stdout. */
#include <stdio.h>

#include "unity.h"

void unity_output_char(int c)
{
    (void)putchar(c);
}

void unity_output_flush(void)
{
    (void)fflush(stdout);
}
