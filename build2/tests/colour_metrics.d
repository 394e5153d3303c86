build2/tests/colour_metrics.o: tests/colour_metrics.c \
 tests/colour_metrics.h
tests/colour_metrics.h:
