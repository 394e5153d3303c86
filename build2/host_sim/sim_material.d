build2/host_sim/sim_material.o: host_sim/sim_material.c \
 host_sim/sim_material.h firmware/vec3.h
host_sim/sim_material.h:
firmware/vec3.h:
