build2/firmware/lsq.o: firmware/lsq.c firmware/lsq.h firmware/frames.h \
 firmware/scan_types.h hal/include/hal_limits.h firmware/vec3.h
firmware/lsq.h:
firmware/frames.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/vec3.h:
