build2/firmware/srgb.o: firmware/srgb.c firmware/srgb.h
firmware/srgb.h:
