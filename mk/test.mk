# make test: the cmocka tests, the scripts beside them, the firmware's own checks (no
# allocator, stack frames), the fuzz corpus replayed; make fuzz; make size.

# ---- tests ----
TEST_SRC := $(filter-out tests/test_util.c,$(wildcard tests/test_*.c))
TEST_SUPPORT := $(BUILD)/tests/test_util.o $(BUILD)/tests/mesh_compare_lib.o $(BUILD)/tests/colour_metrics.o \
	$(BUILD)/tests/tcp_relay.o
TEST_BIN := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
TEST_LIBS = $(shell $(PKG_CONFIG) --libs cmocka libmodbus 2>/dev/null)

# The appliance backends are tested in every build, without their hardware.
TEST_EXTRA_OBJ = $(if $(filter sim,$(HAL)),$(call obj,hal/linux/gpio_gpiod.c hal/linux/v4l2_frame.c hal/linux/camera_v4l2.c) $(LIBCAMERA_OBJ),)
TEST_EXTRA_LIBS = $(shell $(PKG_CONFIG) --libs libgpiod libdrm 2>/dev/null) $(LIBCAMERA_LIBS)

$(BUILD)/tests/%: $(BUILD)/tests/%.o $(TEST_SUPPORT) $(HOST_OBJ) $(TEST_EXTRA_OBJ) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) $(TEST_LDFLAGS) -o $@ $^ $(TEST_LIBS) $(LDLIBS_COMMON) $(TEST_EXTRA_LIBS)

# The storage backend's system calls, failed on purpose (tests/test_storage_faults.c).
$(BUILD)/tests/test_storage_faults: TEST_LDFLAGS = -Wl,--wrap=write,--wrap=fsync,--wrap=rename
# libgpiod answered by the test where no GPIO chip exists (a line held by another program).
GPIOD_WRAPPED := gpiod_chip_open_lookup gpiod_chip_get_line gpiod_line_request_output \
	gpiod_line_consumer gpiod_line_set_value gpiod_line_release gpiod_chip_close
$(BUILD)/tests/test_gpiod: TEST_LDFLAGS = $(foreach f,$(GPIOD_WRAPPED),-Wl,--wrap=$(f))

# The calibration's weighted solve (calib/calib_cv.cpp) needs OpenCV, as scanner-calibrate does:
# built where OpenCV is (make test installs it; not in the arm64 cross-build).
ifeq ($(HAVE_OPENCV),)
TEST_SRC := $(filter-out tests/test_calib_cv.c,$(TEST_SRC))
TEST_BIN := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
endif
$(BUILD)/tests/test_calib_cv: $(BUILD)/calib/calib_cv.o
$(BUILD)/tests/test_calib_cv: TEST_EXTRA_LIBS += $(OPENCV_LIBS) -lstdc++
$(BUILD)/tests/test_calib_cv.o: HOST_CFLAGS += -Icalib

$(BUILD)/tests/test_util.o: tests/test_util.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests -c $< -o $@

$(BUILD)/tests/%.o: tests/%.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests -DSAN=$(SAN) -c $< -o $@

# The firmware must never reference the heap allocator (design card: static buffers only).
check-firmware: $(FW_OBJ)
	@bad=$$(nm -u $(FW_OBJ) | grep -wE 'malloc|calloc|realloc|free|aligned_alloc|posix_memalign'); \
	if [ -n "$$bad" ]; then echo "firmware/ references the allocator:"; echo "$$bad"; exit 1; fi; \
	bad=$$(grep -lE '#include *<(unistd|fcntl|pthread|modbus|gpiod|linux/|sys/)' firmware/*.[ch]); \
	if [ -n "$$bad" ]; then echo "firmware/ includes OS headers: $$bad"; exit 1; fi; \
	echo "check-firmware: no allocator references and no OS headers in firmware/"

# ---- fuzzing: the parsers of what comes from outside (issue 6) ----
# make fuzz: each target under libFuzzer (clang, with ASan + UBSan) for FUZZ_SECONDS, seeded by
# and merged back into tests/fuzz/corpus/<target>/; a crash is written to tests/fuzz/crashes/.
# make test replays the corpus and every crash kept (fuzz-replay-*, built like the suite).
FUZZ_TARGETS := config calib view_ini scan_dir ply modbus
FUZZ_SECONDS ?= 600
FUZZ_LIB_SRC := $(CONFIG_SRC) $(SCAN_DIR_SRC) hal/posix/image_io.c \
	host_sim/sim_mesh.c host_sim/sim_ply_read.c hal/modbus/turntable_modbus.c host_sim/clock_sim.c
FUZZ_CFLAGS = -std=c11 -g -O1 $(HOST_INC) -Itests/fuzz $(PKG_CFLAGS)
FUZZ_LIBS = $(shell $(PKG_CONFIG) --libs inih libmodbus libpng libzstd 2>/dev/null) -lpthread -lm
FUZZ_REPLAY := $(patsubst %,$(BUILD)/tests/fuzz-replay-%,$(FUZZ_TARGETS))

$(BUILD)/tests/fuzz-replay-%: $(call obj,tests/fuzz/replay.c) $(BUILD)/tests/fuzz/fuzz_%.o $(call obj,$(FUZZ_LIB_SRC)) $(BUILD)/libfirmware.a
	$(LINK) $(FUZZ_LIBS)
$(BUILD)/tests/fuzz/%.o: tests/fuzz/%.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests/fuzz -c $< -o $@

FUZZ_BUILD := build/fuzz
$(FUZZ_BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	clang $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link,address,undefined -c $< -o $@
$(FUZZ_BUILD)/fuzz-%: $(FUZZ_BUILD)/tests/fuzz/fuzz_%.o $(patsubst %.c,$(FUZZ_BUILD)/%.o,$(FUZZ_LIB_SRC) $(FW_SRC))
	clang -fsanitize=fuzzer,address,undefined -o $@ $^ $(FUZZ_LIBS)
## fuzz: libFuzzer on the readers (FUZZ_SECONDS=600)
fuzz: deps
	@command -v clang >/dev/null && test -d /usr/lib/llvm-14/lib/clang/14.0.6/lib/linux || scripts/install-deps.sh fuzz
	@$(MAKE) --no-print-directory $(patsubst %,$(FUZZ_BUILD)/fuzz-%,$(FUZZ_TARGETS))
	@for t in $(FUZZ_TARGETS); do \
		mkdir -p $(FUZZ_BUILD)/corpus-$$t tests/fuzz/crashes/$$t; \
		echo "fuzz: $$t for $(FUZZ_SECONDS) s"; \
		$(FUZZ_BUILD)/fuzz-$$t -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 \
			-artifact_prefix=tests/fuzz/crashes/$$t/ $(FUZZ_BUILD)/corpus-$$t tests/fuzz/corpus/$$t \
			2> $(FUZZ_BUILD)/$$t.log || { tail -n 30 $(FUZZ_BUILD)/$$t.log; exit 1; }; \
		grep -E '^stat::number_of_executed_units|^#[0-9]+ *DONE' $(FUZZ_BUILD)/$$t.log | tail -n 2; \
		$(FUZZ_BUILD)/fuzz-$$t -merge=1 tests/fuzz/corpus/$$t $(FUZZ_BUILD)/corpus-$$t 2>/dev/null; \
	done

# Stack frames of firmware/ bounded (the limit is HAL_STACK_FRAME_MAX in hal/include/hal_limits.h;
# checked on the plain build: the sanitizers pad frames).
STACK_LIMIT := $(shell sed -n 's/^\#define HAL_STACK_FRAME_MAX \([0-9]*\)u.*/\1/p' hal/include/hal_limits.h)
## check-stack: every firmware function's stack frame under its limit
check-stack: $(FW_OBJ)
	@scripts/check-stack.sh $(STACK_LIMIT) $(FW_OBJ:.o=.su)

# Static memory of the default build: the scanner's sections, and its static buffers.
## size: static memory of the default build
size: deps $(BUILD)/scanner
	@size -A $(BUILD)/scanner | awk '$$1 ~ /^\.(text|rodata|data|bss)$$/ { printf "%-8s %12d bytes\n", $$1, $$2; \
		if ($$1 != ".text" && $$1 != ".rodata") ram += $$2 } END { printf "static RAM (.data + .bss): %.1f MiB\n", ram / 1048576 }'
	@bench/static_memory.sh $(BUILD)/scanner

# Test-only packages: Open3D reads our PLY (tests/cli.sh); pymodbus and socat are the Modbus
# peers of tests/interop.sh; OpenCV builds scanner-calibrate (tests/calibrate.sh); the Khronos
# glTF validator (npm, pinned in tests/gltf/package-lock.json) checks mesh.glb (tests/cli.sh).
test-deps: deps
	@{ /usr/bin/python3 -c 'import open3d, pymodbus, serial_asyncio' && command -v socat systemd-analyze clang-format && pkg-config --exists libcamera opencv4; } \
		>/dev/null 2>&1 || scripts/install-deps.sh test
	@scripts/install-deps.sh node
	@test -f tests/gltf/node_modules/gltf-validator/package.json || \
		npm ci --prefix tests/gltf --no-audit --no-fund --loglevel=error

# A second make, so that what test-deps installed (libcamera-dev) is seen when it starts.
## test: every test (the README's test command; SAN=1 under ASan and UBSan, VALGRIND=1 under memcheck)
# The build on every core (TEST_JOBS, nproc by default), then the tests in their two lanes.
TEST_JOBS ?= $(shell nproc 2>/dev/null || echo 1)
test: deps test-deps
	@$(MAKE) --no-print-directory -j$(TEST_JOBS) test-build
	@$(MAKE) --no-print-directory test-run
test-build: format-check $(BUILD)/scanner $(CALIB_TOOL) $(WEB_TOOL) $(SIM_TOOLS) $(BUILD)/seccomp-run $(TEST_BIN) $(FUZZ_REPLAY) check-firmware $(if $(filter 0,$(SAN)),check-stack large-build,) linux-build small-build
test-run: test-build
	@RUN_WITH="$(VALGRIND_RUN)" BUILD=$(BUILD) tests/run.sh $(TEST_LANES)

# The two lanes tests/run.sh runs side by side (two cores), about as long as each other.
# LONG_SCRIPTS=0 leaves out the two scripts that scan and calibrate most (tests/objects.sh,
# tests/calibrate.sh: 19 of the 33 minutes the scripts take under the sanitizers, whose code runs in
# the plain make test too): .ci/run's make test SAN=1 does, to stay under its 45 minutes; make
# test SAN=1 alone runs everything.
LONG_SCRIPTS ?= 1
ifeq ($(LONG_SCRIPTS),1)
TEST_LANES = $(TEST_BIN) tests/layers.sh tests/interop.sh tests/fuzz/replay.sh tests/resume.sh tests/objects.sh -- tests/cli.sh tests/calibrate.sh tests/web.sh
else ifeq ($(LONG_SCRIPTS),0)
TEST_LANES = $(TEST_BIN) tests/layers.sh tests/interop.sh tests/fuzz/replay.sh tests/web.sh -- tests/cli.sh tests/resume.sh
else
$(error LONG_SCRIPTS must be 1 or 0, not '$(LONG_SCRIPTS)')
endif

# make test VALGRIND=1: every cmocka test under valgrind memcheck; any invalid access,
# uninitialised use or definite leak fails the test (exit code 99).
VALGRIND ?= 0
VALGRIND_RUN = $(if $(filter 1,$(VALGRIND)),valgrind --quiet --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite --track-origins=yes,)
