/*
 * newlib system calls for the mps2-an386 image: stdout/stderr to UART0, a heap
 * between the end of .bss and the stack (mps2_an386.ld), exit through
 * semihosting. No file system: other calls fail with a proper errno.
 * Linked with -Wl,--undefined=_sbrk so the archive member is always present.
 */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/stat.h>

#include "qemu_mps2.h"

#undef errno
extern int errno;

extern uint8_t __heap_start__, __heap_end__;

int _write(int fd, const char *buf, int len);
int _read(int fd, char *buf, int len);
void *_sbrk(ptrdiff_t incr);
void _exit(int code) __attribute__((noreturn));
int _close(int fd);
int _fstat(int fd, struct stat *st);
int _isatty(int fd);
int _lseek(int fd, int offset, int whence);
int _kill(int pid, int sig);
int _getpid(void);

int _write(int fd, const char *buf, int len)
{
    if (fd != 1 && fd != 2) {
        errno = EBADF;
        return -1;
    }
    for (int i = 0; i < len; i++) {
        uart_putc(buf[i]);
    }
    return len;
}

int _read(int fd, char *buf, int len)
{
    (void)fd;
    (void)buf;
    (void)len;
    return 0; /* end of file: no input */
}

void *_sbrk(ptrdiff_t incr)
{
    static uint8_t *brk = &__heap_start__;
    uint8_t *prev = brk;
    if (incr > (uint8_t *)&__heap_end__ - brk || incr < &__heap_start__ - brk) {
        errno = ENOMEM;
        return (void *)-1;
    }
    brk += incr;
    return prev;
}

void _exit(int code)
{
    semihost_exit(code);
}

int _close(int fd)
{
    (void)fd;
    errno = EBADF;
    return -1;
}

int _fstat(int fd, struct stat *st)
{
    (void)fd;
    st->st_mode = S_IFCHR; /* a character device: stdio line-buffers it */
    return 0;
}

int _isatty(int fd)
{
    return (fd >= 0 && fd <= 2) ? 1 : 0;
}

int _lseek(int fd, int offset, int whence)
{
    (void)fd;
    (void)offset;
    (void)whence;
    return 0;
}

int _kill(int pid, int sig)
{
    (void)pid;
    (void)sig;
    errno = EINVAL;
    return -1;
}

int _getpid(void)
{
    return 1;
}
