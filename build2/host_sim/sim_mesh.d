build2/host_sim/sim_mesh.o: host_sim/sim_mesh.c host_sim/sim_mesh.h \
 firmware/vec3.h
host_sim/sim_mesh.h:
firmware/vec3.h:
