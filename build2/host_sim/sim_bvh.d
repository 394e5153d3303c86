build2/host_sim/sim_bvh.o: host_sim/sim_bvh.c host_sim/sim_bvh.h \
 host_sim/sim_mesh.h firmware/vec3.h
host_sim/sim_bvh.h:
host_sim/sim_mesh.h:
firmware/vec3.h:
