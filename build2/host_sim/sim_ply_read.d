build2/host_sim/sim_ply_read.o: host_sim/sim_ply_read.c \
 host_sim/sim_mesh.h
host_sim/sim_mesh.h:
