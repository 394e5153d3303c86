/* seccomp-run: run a command under a system-call allow-list, as systemd's SystemCallFilter= does
 * for the installed unit (a call outside the list kills the process with SIGSYS), so a test can
 * show that the scanner works under the unit's filter without a running systemd.
 * Usage: seccomp-run LIST -- COMMAND [ARG...]   (LIST: one system call name a line) */
#define _GNU_SOURCE
#include <seccomp.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    if (argc < 4 || strcmp(argv[2], "--") != 0) {
        fprintf(stderr, "usage: seccomp-run LIST -- COMMAND [ARG...]\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "r");
    scmp_filter_ctx ctx = seccomp_init(SCMP_ACT_KILL_PROCESS);
    if (f == NULL || ctx == NULL) {
        perror(argv[1]);
        return 2;
    }
    char name[128];
    int allowed = 0;
    while (fscanf(f, "%127s", name) == 1) {
        int nr = seccomp_syscall_resolve_name(name);
        if (nr == __NR_SCMP_ERROR)
            continue; /* a call this architecture does not have */
        if (seccomp_rule_add(ctx, SCMP_ACT_ALLOW, nr, 0) == 0)
            allowed++;
    }
    fclose(f);
    /* execve itself must pass: systemd installs the filter before it, and allows it */
    seccomp_rule_add(ctx, SCMP_ACT_ALLOW, SCMP_SYS(execve), 0);
    if (allowed == 0 || seccomp_load(ctx) != 0) {
        fprintf(stderr, "seccomp-run: cannot load a filter of %d calls\n", allowed);
        return 2;
    }
    execvp(argv[3], argv + 3);
    perror(argv[3]);
    return 127;
}
