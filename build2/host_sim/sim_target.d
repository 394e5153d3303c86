build2/host_sim/sim_target.o: host_sim/sim_target.c host_sim/sim_target.h \
 host_sim/sim_mesh.h firmware/vec3.h
host_sim/sim_target.h:
host_sim/sim_mesh.h:
firmware/vec3.h:
