build2/host_sim/sim_jpeg.o: host_sim/sim_jpeg.c host_sim/sim_jpeg.h
host_sim/sim_jpeg.h:
