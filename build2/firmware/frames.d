build2/firmware/frames.o: firmware/frames.c firmware/frames.h \
 firmware/scan_types.h hal/include/hal_limits.h firmware/vec3.h
firmware/frames.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/vec3.h:
