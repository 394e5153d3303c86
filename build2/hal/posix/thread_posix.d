build2/hal/posix/thread_posix.o: hal/posix/thread_posix.c \
 hal/posix/thread_posix.h
hal/posix/thread_posix.h:
