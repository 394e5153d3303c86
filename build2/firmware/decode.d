build2/firmware/decode.o: firmware/decode.c firmware/decode.h \
 firmware/gray.h firmware/scan_types.h hal/include/hal_limits.h \
 firmware/lsq.h firmware/frames.h firmware/vec3.h
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/lsq.h:
firmware/frames.h:
firmware/vec3.h:
