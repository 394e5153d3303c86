build2/host_sim/pty_link.o: host_sim/pty_link.c host_sim/pty_link.h
host_sim/pty_link.h:
