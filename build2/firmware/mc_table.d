build2/firmware/mc_table.o: firmware/mc_table.c firmware/mc_table.h \
 firmware/vec3.h
firmware/mc_table.h:
firmware/vec3.h:
