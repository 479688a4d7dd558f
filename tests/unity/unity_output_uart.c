/* Unity output port for the QEMU mps2-an386 target: characters to CMSDK UART0. */
#include "qemu_mps2.h"
#include "unity.h"

void unity_output_char(int c)
{
    uart_putc((char)c);
}

void unity_output_flush(void)
{
    /* The UART model transmits immediately: nothing buffered. */
}
