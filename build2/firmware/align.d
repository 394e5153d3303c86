build2/firmware/align.o: firmware/align.c firmware/align.h \
 firmware/frames.h firmware/scan_types.h hal/include/hal_limits.h \
 firmware/vec3.h firmware/lsq.h
firmware/align.h:
firmware/frames.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/vec3.h:
firmware/lsq.h:
