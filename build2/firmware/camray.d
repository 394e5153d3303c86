build2/firmware/camray.o: firmware/camray.c firmware/camray.h \
 firmware/scan_types.h hal/include/hal_limits.h firmware/vec3.h \
 firmware/lens.h
firmware/camray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/vec3.h:
firmware/lens.h:
