/*
 * newlib system calls of an STM32 image (G4 and F4 alike): no console (the
 * serial link is the application's), a heap between the end of .bss and the
 * reserved stack (__heap_start__ .. __heap_end__ of the chip's linker
 * script), no file system: every other call fails with an errno. _exit turns
 * the gates off and waits for the watchdog (stm32_fault_halt, the chip
 * start-up's).
 */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/stat.h>

#include "stm32_startup.h"

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
    (void)fd;
    (void)buf;
    return len; /* discarded */
}

int _read(int fd, char *buf, int len)
{
    (void)fd;
    (void)buf;
    (void)len;
    return 0;
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
    (void)code;
    stm32_fault_halt();
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
    st->st_mode = S_IFCHR;
    return 0;
}

int _isatty(int fd)
{
    (void)fd;
    return 1;
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
