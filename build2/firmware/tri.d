build2/firmware/tri.o: firmware/tri.c firmware/tri.h firmware/decode.h \
 firmware/gray.h firmware/scan_types.h hal/include/hal_limits.h \
 firmware/camray.h firmware/vec3.h firmware/lens.h
firmware/tri.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/camray.h:
firmware/vec3.h:
firmware/lens.h:
