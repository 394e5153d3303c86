build2/tests/tcp_relay.o: tests/tcp_relay.c tests/tcp_relay.h
tests/tcp_relay.h:
