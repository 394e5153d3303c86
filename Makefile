# Turntable colour 3D scanner: build, test and run. See README.md.
#   make              build/scanner (HAL=sim by default; HAL=linux for the appliance)
#   make test         every unit and integration test (SAN=1: under ASan + UBSan)
#   make run          a simulated scan with config/sim.ini
#   make CROSS_COMPILE=aarch64-linux-gnu-   the appliance for arm64 (build/aarch64-linux-gnu/)
#   make test-arm64   the unit tests built for arm64, run under qemu-aarch64
SAN ?= 0
CC ?= cc
PKGS := inih libpng libzstd libjpeg libdrm cmocka libmodbus libgpiod libseccomp
PKG_CONFIG := pkg-config
DEPS_SET :=
DEPS_TOOLS := $(CC)
BUILD := build
# Cross build with Debian's cross compiler and the target's -dev packages (multiarch): the
# appliance (HAL=linux) unless told otherwise, in a build directory of its own.
ifneq ($(CROSS_COMPILE),)
HAL ?= linux
CC := $(CROSS_COMPILE)gcc
CXX := $(CROSS_COMPILE)g++
AR := $(CROSS_COMPILE)ar
TRIPLET := $(patsubst %-,%,$(CROSS_COMPILE))
PKG_CONFIG := PKG_CONFIG_LIBDIR=/usr/lib/$(TRIPLET)/pkgconfig:/usr/share/pkgconfig pkg-config
DEPS_SET := $(TRIPLET)
DEPS_TOOLS := $(CC) qemu-$(firstword $(subst -, ,$(TRIPLET)))
BUILD := build/$(TRIPLET)
endif
HAL ?= sim

ifeq ($(HAL),sim)
else ifeq ($(HAL),linux)
else
$(error HAL must be sim or linux, not '$(HAL)')
endif

OPT := -O2
ifeq ($(SAN),1)
BUILD := $(BUILD)/san
OPT := -O1 -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
endif
# Compile-time limits (hal/include/hal_limits.h): default, or small for a board with 512 MB.
# Every object depends on them, so each set builds in its own directory.
LIMITS ?= default
ifeq ($(LIMITS),small)
BUILD := $(BUILD)/small
LIMITS_CFLAGS := -DHAL_LIMITS_SMALL
else ifneq ($(LIMITS),default)
$(error LIMITS must be default or small, not '$(LIMITS)')
endif

# HAL=linux objects live apart so that the two builds never mix (also when cross-built).
ifeq ($(HAL),linux)
BUILD := $(BUILD)/linux
endif

WARN := -std=c11 -Wall -Wextra -Werror
CFLAGS_COMMON := $(WARN) $(OPT) $(LIMITS_CFLAGS) -g -MMD -MP
# firmware/ sees the world only through hal/include.
FW_CFLAGS := $(CFLAGS_COMMON) -Ihal/include -Ifirmware -fstack-usage
PKG_CFLAGS = $(shell $(PKG_CONFIG) --cflags $(PKGS) 2>/dev/null)
PKG_LIBS = $(shell $(PKG_CONFIG) --libs inih libpng libzstd libjpeg libmodbus 2>/dev/null) -lpthread
# Each layer is compiled with only the include paths it may use, so an include that runs back up
# (hal/ or host_sim/ reaching into app/, board/ into app/) does not compile (docs/architecture.md;
# tests/layers.sh shows it). Everyone sees hal/include; a layer's paths are INC_<its directory>.
INC_hal/posix := -Ihal/posix
INC_hal/modbus := -Ihal/modbus
INC_hal/linux := -Ihal/linux
# The simulator agrees with firmware/ on frames, the pattern sequence and the calibration's plain
# data (frames.h, gray.h, scan_types.h, vec3.h), and with the Modbus client on the register map
# it serves (hal/modbus/tt_regs.h).
INC_host_sim := -Ihost_sim -Ifirmware -Ihal/modbus
# The board composes the backends and the simulator; app/ fills its struct board_config.
INC_board := -Iboard -Ifirmware -Ihal/posix -Ihal/modbus -Ihal/linux -Ihost_sim
# The scanner program: the firmware, the board, and the settings structs of the backends and the
# simulator it reads from a config (turntable_modbus.h, sim_config.h).
INC_app := -Iapp -Iboard -Ifirmware -Ihal/posix -Ihal/modbus -Ihost_sim
# The web server: the report's pictures and the config's reader from app/ (config.h names the
# board's settings struct); no board code is linked: it never touches a device.
INC_web := -Iweb -Iapp -Iboard -Ifirmware -Ihal/posix -Ihal/modbus -Ihost_sim $(shell $(PKG_CONFIG) --cflags libcjson 2>/dev/null)
# Tests, benchmarks and fuzzers see everything.
ALL_INC := -Ifirmware -Iapp -Iboard -Ihal/posix -Ihal/linux -Ihal/modbus -Ihost_sim
HOST_INC := -Ihal/include $(ALL_INC)
INC_tests := $(ALL_INC)
INC_tests/fuzz := $(ALL_INC)
INC_bench := $(ALL_INC)
LAYER_INC = -Ihal/include $(INC_$(patsubst %/,%,$(dir $<)))
HOST_CFLAGS = $(CFLAGS_COMMON) $(LAYER_INC) $(PKG_CFLAGS)
LDFLAGS_COMMON := $(OPT) -g
LDLIBS_COMMON = $(PKG_LIBS) -lm

FW_SRC := $(wildcard firmware/*.c) hal/hal.c
POSIX_SRC := $(wildcard hal/posix/*.c) $(wildcard hal/modbus/*.c)
APP_LIB_SRC := app/config.c app/frame_writer.c app/ini_schema.c app/patterns.c app/report.c app/scan_dir.c app/scan_job.c app/white_cal.c board/board_frame.c
SIM_SRC := $(filter-out host_sim/turntable_sim_main.c,$(wildcard host_sim/*.c)) board/board_sim.c
LINUX_SRC := $(wildcard hal/linux/*.c) board/board_linux.c board/board_display.c
# The libcamera backend (C++) is built where libcamera is found (Raspberry Pi OS, or Debian's
# libcamera-dev, which make test installs); without it [camera] backend = libcamera says so.
HAVE_LIBCAMERA := $(shell $(PKG_CONFIG) --exists libcamera 2>/dev/null && echo 1)
LIBCAMERA_OBJ = $(if $(HAVE_LIBCAMERA),$(BUILD)/hal/linux/camera_libcamera.o,)
LIBCAMERA_LIBS = $(if $(HAVE_LIBCAMERA),$(shell $(PKG_CONFIG) --libs libcamera) -lstdc++,)
HOST_CFLAGS += $(if $(HAVE_LIBCAMERA),-DHAVE_LIBCAMERA,)
BOARD_SRC := $(if $(filter sim,$(HAL)),$(SIM_SRC),$(LINUX_SRC))
# The calibration (scanner calibrate) is its own program, scanner-calibrate, built where OpenCV
# 4 is found (Debian's libopencv-dev for its pkg-config file and libopencv-contrib-dev for ArUco,
# which make test installs): a scan never loads
# OpenCV. scanner execs it for 'scanner calibrate'.
HAVE_OPENCV := $(shell $(PKG_CONFIG) --exists opencv4 2>/dev/null && echo 1)
CALIB_SRC := app/calibrate.c app/calib_solve.c app/calib_files.c
OPENCV_LIBS := -lopencv_aruco -lopencv_calib3d -lopencv_imgproc -lopencv_core
CALIB_TOOL := $(if $(HAVE_OPENCV),$(BUILD)/scanner-calibrate,)
# The web interface (scanner serve) is its own program too, scanner-web: civetweb and cJSON
# (Debian's libcivetweb-dev and libcjson-dev, which make installs); a scan never loads them.
# Not cross-built: the board runs the native build's (docs/web.md).
HAVE_CIVETWEB := $(if $(CROSS_COMPILE),,$(shell test -f /usr/include/civetweb.h && $(PKG_CONFIG) --exists libcjson 2>/dev/null && echo 1))
WEB_SRC := web/serve.c web/api.c web/jobs.c
WEB_TOOL := $(if $(HAVE_CIVETWEB),$(BUILD)/scanner-web,)
BOARD_LIBS = $(if $(filter linux,$(HAL)),$(shell $(PKG_CONFIG) --libs libgpiod libdrm 2>/dev/null) $(LIBCAMERA_LIBS),)

obj = $(patsubst %.c,$(BUILD)/%.o,$(1))
FW_OBJ := $(call obj,$(FW_SRC))
HOST_OBJ := $(call obj,$(POSIX_SRC) $(APP_LIB_SRC) $(BOARD_SRC)) $(if $(filter linux,$(HAL)),$(LIBCAMERA_OBJ),)
MAIN_OBJ := $(call obj,app/main.c)

.PHONY: serve test-browser check-blender seccomp-tool vivid-tool all deps test-deps test test-run run-complete linux-build small-build install check-stack size fuzz errors-doc test-arm64 test-arm64-full test-gpio-chip arm64-check-elf arm64-run-tests run clean format docs check-firmware bench measure measure-scan interop-meshlab bench-callgrind eval calibrate-demo measure-calib
SIM_TOOLS := $(if $(filter sim,$(HAL)),$(BUILD)/turntable-sim $(BUILD)/tt-client $(BUILD)/mesh-compare $(BUILD)/colour-eval $(BUILD)/relight-eval,)
all: deps $(BUILD)/scanner $(CALIB_TOOL) $(WEB_TOOL) $(SIM_TOOLS)

# Install missing Debian packages (fresh Debian 12): only when pkg-config cannot find them.
deps:
	@{ $(PKG_CONFIG) --exists $(PKGS) && command -v $(DEPS_TOOLS) && { [ -n "$(CROSS_COMPILE)" ] || \
		{ test -f /usr/include/civetweb.h && $(PKG_CONFIG) --exists libcjson; }; }; } >/dev/null 2>&1 || \
		scripts/install-deps.sh $(DEPS_SET)

# The firmware's flags in a file that changes only when they do: objects built with other
# flags (say, before -fstack-usage) are rebuilt.
FW_FLAGS_STAMP := $(BUILD)/firmware.flags
$(FW_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@); echo '$(FW_CFLAGS)' | cmp -s - $@ || echo '$(FW_CFLAGS)' > $@
FORCE:

$(FW_OBJ): $(BUILD)/%.o: %.c $(FW_FLAGS_STAMP) | deps
	@mkdir -p $(dir $@)
	$(CC) $(FW_CFLAGS) $(FW_EXTRA) -c $< -o $@

# The decoder's inner loops are written to be vectorised; GCC 12 does that from -O3.
$(BUILD)/firmware/decode.o: FW_EXTRA = -O3

$(BUILD)/%.o: %.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -c $< -o $@

$(BUILD)/%.o: %.cpp | deps
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 -Wall -Wextra -Werror $(OPT) $(LIMITS_CFLAGS) -g -MMD -MP -Ihal/include -Ihal/linux $(shell $(PKG_CONFIG) --cflags libcamera 2>/dev/null) -c $< -o $@

$(BUILD)/libfirmware.a: $(FW_OBJ)
	$(AR) rcs $@ $^

$(BUILD)/scanner: $(MAIN_OBJ) $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(BOARD_LIBS)

$(BUILD)/app/main_calibrate.o: app/main.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -DSCANNER_CALIBRATE -c $< -o $@
$(BUILD)/app/calib_cv.o: app/calib_cv.cpp app/calib_cv.h | deps
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 -Wall -Wextra -Werror $(OPT) -g -MMD -MP -Iapp $(shell $(PKG_CONFIG) --cflags opencv4 2>/dev/null) -c $< -o $@
$(BUILD)/scanner-calibrate: $(BUILD)/app/main_calibrate.o $(call obj,$(CALIB_SRC)) $(BUILD)/app/calib_cv.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CXX) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(BOARD_LIBS) $(OPENCV_LIBS)

$(BUILD)/web/serve.o: HOST_CFLAGS += -DWEB_WWW_DIR='"$(CURDIR)/web/www"'
$(BUILD)/scanner-web: $(call obj,$(WEB_SRC) app/report.c app/scan_dir.c app/config.c app/ini_schema.c hal/posix/image_io.c hal/posix/storage_posix.c) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) -lcivetweb -lcjson

# The simulated controller as its own program, and the client as a command (interop tests).
$(BUILD)/turntable-sim: $(call obj,host_sim/turntable_sim_main.c host_sim/tt_server.c host_sim/tt_ctrl.c)
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON)
$(BUILD)/tt-client: $(call obj,tests/tt_client_main.c hal/modbus/turntable_modbus.c hal/posix/clock_posix.c) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON)

# Runs a command under a system-call allow-list as the systemd unit's filter does (tests only).
$(BUILD)/seccomp-run: tests/seccomp_run.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(WARN) $(OPT) -g -o $@ $< $(shell $(PKG_CONFIG) --libs libseccomp 2>/dev/null)
seccomp-tool: $(BUILD)/seccomp-run
# The V4L2 backend against vivid in the arm64 VM (tests/gpio_chip.sh); HAL=linux builds.
$(BUILD)/vivid-capture: $(call obj,tests/vivid_capture.c hal/linux/camera_v4l2.c hal/linux/v4l2_frame.c) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ -lm
vivid-tool: $(BUILD)/vivid-capture $(BUILD)/drm-show
# The HDMI projector against virtio-gpu in the same VM.
$(BUILD)/drm-show: $(call obj,tests/drm_show.c board/board_display.c hal/linux/projector_drm.c) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(shell $(PKG_CONFIG) --libs libdrm) -lm

$(BUILD)/mesh-compare: $(call obj,tests/mesh_compare.c tests/mesh_compare_lib.c host_sim/sim_bvh.c host_sim/sim_mesh.c host_sim/sim_ply_read.c app/config.c app/ini_schema.c app/scan_dir.c hal/posix/image_io.c) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON)

EVAL_SIM_SRC := tests/colour_metrics.c host_sim/sim_bvh.c host_sim/sim_mesh.c host_sim/sim_ply_read.c host_sim/sim_rig.c host_sim/sim_jpeg.c host_sim/sim_target.c host_sim/sim_material.c app/config.c app/ini_schema.c app/scan_dir.c hal/posix/image_io.c hal/posix/storage_posix.c
$(BUILD)/colour-eval: $(call obj,tests/colour_eval.c $(EVAL_SIM_SRC)) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON)
$(BUILD)/relight-eval: $(call obj,tests/relight_eval.c $(EVAL_SIM_SRC)) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON)

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
FUZZ_LIB_SRC := app/config.c app/ini_schema.c app/scan_dir.c hal/posix/image_io.c \
	host_sim/sim_mesh.c host_sim/sim_ply_read.c hal/modbus/turntable_modbus.c host_sim/clock_sim.c
FUZZ_CFLAGS = -std=c11 -g -O1 $(HOST_INC) -Itests/fuzz $(PKG_CFLAGS)
FUZZ_LIBS = $(shell $(PKG_CONFIG) --libs inih libmodbus libpng libzstd 2>/dev/null) -lpthread -lm
FUZZ_REPLAY := $(patsubst %,$(BUILD)/tests/fuzz-replay-%,$(FUZZ_TARGETS))

$(BUILD)/tests/fuzz-replay-%: $(call obj,tests/fuzz/replay.c) $(BUILD)/tests/fuzz/fuzz_%.o $(call obj,$(FUZZ_LIB_SRC)) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(FUZZ_LIBS)
$(BUILD)/tests/fuzz/%.o: tests/fuzz/%.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests/fuzz -c $< -o $@

FUZZ_BUILD := build/fuzz
$(FUZZ_BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	clang $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link,address,undefined -c $< -o $@
$(FUZZ_BUILD)/fuzz-%: $(FUZZ_BUILD)/tests/fuzz/fuzz_%.o $(patsubst %.c,$(FUZZ_BUILD)/%.o,$(FUZZ_LIB_SRC) $(FW_SRC))
	clang -fsanitize=fuzzer,address,undefined -o $@ $^ $(FUZZ_LIBS)
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
check-stack: $(FW_OBJ)
	@scripts/check-stack.sh $(STACK_LIMIT) $(FW_OBJ:.o=.su)

# Static memory of the default build: the scanner's sections, and the firmware's buffers.
size: deps $(BUILD)/scanner $(BUILD)/libfirmware.a
	@size -A $(BUILD)/scanner | awk '$$1 ~ /^\.(text|rodata|data|bss)$$/ { printf "%-8s %12d bytes\n", $$1, $$2; \
		if ($$1 != ".text" && $$1 != ".rodata") ram += $$2 } END { printf "static RAM (.data + .bss): %.1f MiB\n", ram / 1048576 }'
	@bench/static_memory.sh $(BUILD)/libfirmware.a

# Test-only packages: Open3D reads our PLY (tests/cli.sh); pymodbus and socat are the Modbus
# peers of tests/interop.sh; OpenCV builds scanner-calibrate (tests/calibrate.sh); the Khronos
# glTF validator (npm, pinned in tests/gltf/package-lock.json) checks mesh.glb (tests/cli.sh).
test-deps: deps
	@{ /usr/bin/python3 -c 'import open3d, pymodbus, serial_asyncio' && command -v socat systemd-analyze && pkg-config --exists libcamera opencv4; } \
		>/dev/null 2>&1 || scripts/install-deps.sh test
	@scripts/install-deps.sh node
	@test -f tests/gltf/node_modules/gltf-validator/package.json || \
		npm ci --prefix tests/gltf --no-audit --no-fund --loglevel=error

# A second make, so that what test-deps installed (libcamera-dev) is seen when it starts.
test: deps test-deps
	@$(MAKE) --no-print-directory test-run
test-run: $(BUILD)/scanner $(CALIB_TOOL) $(WEB_TOOL) $(SIM_TOOLS) $(BUILD)/seccomp-run $(TEST_BIN) $(FUZZ_REPLAY) check-firmware $(if $(filter 0,$(SAN)),check-stack,) linux-build small-build
	@RUN_WITH="$(VALGRIND_RUN)" BUILD=$(BUILD) tests/run.sh $(TEST_BIN) tests/layers.sh tests/interop.sh tests/fuzz/replay.sh tests/resume.sh -- tests/cli.sh tests/calibrate.sh

# make test VALGRIND=1: every cmocka test under valgrind memcheck; any invalid access,
# uninitialised use or definite leak fails the test (exit code 99).
VALGRIND ?= 0
VALGRIND_RUN = $(if $(filter 1,$(VALGRIND)),valgrind --quiet --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite --track-origins=yes,)

# arm64 (a Raspberry Pi 4 or 5 on a 64-bit OS): the appliance's scanner cross-built and checked
# to be an AArch64 ELF, then every cmocka unit test built for arm64 and run under qemu-aarch64
# (Debian's qemu-user; the arm64 loader and libraries come with the multiarch -dev packages).
ARM64 := CROSS_COMPILE=aarch64-linux-gnu-
# Emulated, the tests that render whole simulated scans take many minutes each: test-arm64 runs
# the others (every firmware algorithm, config, Modbus, backends); test-arm64-full runs them all.
ARM64_SLOW := test_colour test_nomalloc test_ply test_safety test_scan test_scan_faults test_sim test_view
ARM64_TESTS = $(filter-out $(addprefix $(BUILD)/tests/,$(ARM64_SLOW)),$(TEST_BIN))
test-arm64:
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux deps
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux arm64-check-elf
	@$(MAKE) --no-print-directory $(ARM64) HAL=sim arm64-run-tests
test-arm64-full:
	@$(MAKE) --no-print-directory $(ARM64) HAL=sim deps
	@$(MAKE) --no-print-directory $(ARM64) HAL=sim ARM64_SLOW= arm64-run-tests
# The GPIO backend against a real kernel GPIO chip (the PL061 of qemu's arm64 "virt" machine),
# with another program holding one of the lines; the default build on 1 GB, the LIMITS=small
# build on 512 MB: tests/gpio_chip.sh. About two minutes.
test-gpio-chip:
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux deps
	@{ command -v qemu-system-aarch64 && command -v cpio && command -v systemd-analyze && command -v socat; } >/dev/null 2>&1 || scripts/install-deps.sh gpio-chip
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux all
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux LIMITS=small all
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux seccomp-tool vivid-tool
	@tests/run.sh tests/gpio_chip.sh
arm64-check-elf: $(BUILD)/scanner
	@$(CROSS_COMPILE)readelf -h $< | grep -q 'Machine: *AArch64' && echo "$<: AArch64 ELF"
arm64-run-tests: $(TEST_BIN)
	@RUN_WITH=qemu-aarch64 BUILD=$(BUILD) tests/run.sh $(ARM64_TESTS)

# The appliance, installed: the HAL=linux scanner, the example configs in /etc/scanner (an edited
# one is kept; the new example goes beside it as .dist), the systemd unit, its user and groups
# (sysusers.d) and the GPIO group rule (udev). DESTDIR stages it (packaging, tests).
PREFIX ?= /usr/local
SYSCONFDIR ?= /etc
UNITDIR ?= /lib/systemd/system
DOCDIR ?= $(PREFIX)/share/doc/scanner
install: linux-build
	install -D -m 0755 $(LINUX_BUILD)/scanner $(DESTDIR)$(PREFIX)/bin/scanner
	install -d -m 0755 $(DESTDIR)$(SYSCONFDIR)/scanner
	@for f in config/pi-v4l2.ini config/pi-libcamera.ini; do \
		dest=$(DESTDIR)$(SYSCONFDIR)/scanner/$$(basename $$f); \
		if [ -e $$dest ] && ! cmp -s $$f $$dest; then dest=$$dest.dist; fi; \
		echo "install -m 0644 $$f $$dest"; install -m 0644 $$f $$dest; \
	done
	@mkdir -p $(BUILD)/deploy
	sed -e 's|@BINDIR@|$(PREFIX)/bin|g' -e 's|@SYSCONFDIR@|$(SYSCONFDIR)|g' -e 's|@DOCDIR@|$(DOCDIR)|g' \
		'config/deploy/scanner@.service' > '$(BUILD)/deploy/scanner@.service'
	install -D -m 0644 '$(BUILD)/deploy/scanner@.service' '$(DESTDIR)$(UNITDIR)/scanner@.service'
	install -D -m 0644 config/deploy/scanner.sysusers $(DESTDIR)/usr/lib/sysusers.d/scanner.conf
	install -D -m 0644 config/deploy/60-scanner-gpio.rules $(DESTDIR)/usr/lib/udev/rules.d/60-scanner-gpio.rules
	install -D -m 0644 docs/deploy.md $(DESTDIR)$(DOCDIR)/deploy.md
	@if [ -x $(LINUX_BUILD)/scanner-web ]; then \
		echo "install scanner-web, its page and scanner-web@.service"; \
		install -D -m 0755 $(LINUX_BUILD)/scanner-web $(DESTDIR)$(PREFIX)/bin/scanner-web; \
		rm -rf $(DESTDIR)$(PREFIX)/share/scanner/www; mkdir -p $(DESTDIR)$(PREFIX)/share/scanner; \
		cp -R web/www $(DESTDIR)$(PREFIX)/share/scanner/www; \
		sed -e 's|@BINDIR@|$(PREFIX)/bin|g' -e 's|@SYSCONFDIR@|$(SYSCONFDIR)|g' -e 's|@DOCDIR@|$(DOCDIR)|g' \
			'config/deploy/scanner-web@.service' > '$(BUILD)/deploy/scanner-web@.service'; \
		install -D -m 0644 '$(BUILD)/deploy/scanner-web@.service' '$(DESTDIR)$(UNITDIR)/scanner-web@.service'; \
		install -D -m 0644 docs/web.md $(DESTDIR)$(DOCDIR)/web.md; \
	fi
	@# The web page's token: made here, once, never a default (docs/web.md)
	@if [ ! -e $(DESTDIR)$(SYSCONFDIR)/scanner/web-token ]; then \
		(umask 077; head -c 18 /dev/urandom | base64 > $(DESTDIR)$(SYSCONFDIR)/scanner/web-token); \
		echo "make install: the web page's token is in $(SYSCONFDIR)/scanner/web-token (readable by root only)"; \
	fi
	@[ -n "$(DESTDIR)" ] || echo "make install: now run: systemd-sysusers; udevadm control --reload; udevadm trigger; systemctl daemon-reload"

# The appliance's scanner (every backend compiled; tests/cli.sh runs its selftest).
LINUX_BUILD := $(if $(filter linux,$(HAL)),$(BUILD),$(BUILD)/linux)
linux-build: deps
	@$(MAKE) --no-print-directory HAL=linux SAN=$(SAN) $(LINUX_BUILD)/scanner $(if $(HAVE_CIVETWEB),$(LINUX_BUILD)/scanner-web,)
# The simulator build with LIMITS=small (a 512 MB board), for tests/cli.sh.
small-build: deps
	@$(MAKE) --no-print-directory LIMITS=small SAN=$(SAN) $(BUILD)/small/scanner

run: deps $(BUILD)/scanner
	$(BUILD)/scanner scan --config config/sim.ini

# The web interface on the simulator (docs/web.md): http://127.0.0.1:8080, Ctrl-C ends it. A
# second make, so that civetweb, if deps just installed it, is seen.
serve: deps
	@$(MAKE) --no-print-directory $(BUILD)/scanner $(BUILD)/scanner-web
	@echo "make serve: the scanner's page is at http://127.0.0.1:8080 (Ctrl-C ends it)"
	$(BUILD)/scanner serve --config config/sim.ini --config config/sim-glossy.ini --listen 127.0.0.1:8080

# The page and its API in Debian's Chromium (tests/browser/browser_test.mjs, about 90 s; in CI).
# The pictures it takes of the page are in $(BUILD)/browser/ (docs/web/ has a pair).
test-browser: deps
	@command -v chromium >/dev/null 2>&1 || scripts/install-deps.sh browser
	@scripts/install-deps.sh node
	@test -f tests/browser/node_modules/playwright-core/package.json || \
		npm ci --prefix tests/browser --no-audit --no-fund --loglevel=error
	@$(MAKE) --no-print-directory $(BUILD)/scanner $(BUILD)/scanner-web
	node tests/browser/browser_test.mjs $(BUILD)

# Blender 3.4 (Debian's, installed if missing; not in CI: 66 packages) imports a scan's
# mesh.ply, mesh.obj, mesh.stl and mesh.glb upright and at the object's size in a millimetre scene.
check-blender: deps $(BUILD)/scanner
	@command -v blender >/dev/null || scripts/install-deps.sh blender
	@rm -rf $(BUILD)/blender-scan
	$(BUILD)/scanner scan --config config/sim.ini --out $(BUILD)/blender-scan > /dev/null
	@blender -b --python-exit-code 1 -P tests/blender_import.py -- $(BUILD)/blender-scan 150 \
		> $(BUILD)/blender.log 2>&1 || { cat $(BUILD)/blender.log; exit 1; }
	@grep '^blender:' $(BUILD)/blender.log
	@rm -rf $(BUILD)/blender-scan

# The bunny in two passes (upright, then on its side), one model: scans/sim-complete/latest/.
run-complete: deps $(BUILD)/scanner $(BUILD)/mesh-compare
	$(BUILD)/scanner scan --config config/sim-complete.ini
	$(BUILD)/mesh-compare --align scans/sim-complete/latest/mesh.ply scans/sim-complete/latest/truth_mesh.ply

docs: $(BUILD)/scanner
	$(BUILD)/scanner config-doc > docs/config.md

# docs/errors.md: bad inputs and the messages they get (tests/cli.sh checks it is current).
errors-doc: deps $(BUILD)/scanner linux-build
	scripts/errors-table.sh $(BUILD) > docs/errors.md

format:
	clang-format -i $$(git ls-files '*.c' '*.h')

clean:
	rm -rf build

.SECONDARY:

-include $(shell find $(BUILD) -name '*.d' -type f 2>/dev/null)

# Decoding rate, depth error and time per view on the simulator (numbers for the notes).
$(BUILD)/measure_view: $(BUILD)/tests/measure_view.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(BOARD_LIBS)
measure: deps $(BUILD)/measure_view
	$(BUILD)/measure_view config/sim.ini config/sim-limit.ini config/sim-glossy.ini config/sim-concave.ini

# Intrinsic colour (issue 4): Jost et al.'s comparison reproduced on the simulator, written to
# docs/colour-eval/ (table as Markdown and CSV, close-up PNGs of a view boundary). About 20 minutes.
EVAL_DIR ?= docs/colour-eval
eval: deps $(BUILD)/scanner $(BUILD)/colour-eval $(BUILD)/relight-eval
	tests/colour_eval.sh $(BUILD) $(EVAL_DIR)

# Full simulated scans measured against the true surface, with a turntable that misses its
# angle by up to 1 and 2 degrees (each view's angle as reported, registered and true), and peak
# memory for 8 and 24 views.
measure-scan: deps $(BUILD)/scanner $(BUILD)/mesh-compare $(BUILD)/measure-registration
	scripts/measure-scan.sh $(BUILD)

# MeshLab opens a scan's mesh (installs MeshLab and Xvfb when missing: large, so not in test).
interop-meshlab: deps $(BUILD)/scanner
	rm -rf $(BUILD)/meshlab-scan
	$(BUILD)/scanner scan --config config/sim.ini --out $(BUILD)/meshlab-scan > /dev/null
	tests/interop_meshlab.sh $(BUILD)/meshlab-scan

# Each view's angle as reported, as registered and as true (tests/measure_registration.c).
$(BUILD)/measure-registration: $(call obj,tests/measure_registration.c app/config.c app/ini_schema.c app/scan_dir.c hal/posix/image_io.c) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON)

# The calibration's accuracy (tests/measure_calib.c): a calibration against the true rig.
$(BUILD)/measure-calib: $(call obj,tests/measure_calib.c app/config.c app/ini_schema.c) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON)

# Calibration of the simulated demo rig from scratch (scans/calib-demo/), and how close it is:
# make calibrate-demo prints the table parameter | true | nominal | recovered | error and scans
# the bunny with the result; make measure-calib also scans with the true and the nominal file.
# A few minutes each (docs/calibration.md).
calibrate-demo: deps $(BUILD)/scanner $(BUILD)/scanner-calibrate $(BUILD)/mesh-compare $(BUILD)/measure-calib
	scripts/measure-calib.sh $(BUILD)
measure-calib: deps $(BUILD)/scanner $(BUILD)/scanner-calibrate $(BUILD)/mesh-compare $(BUILD)/measure-calib
	scripts/measure-calib.sh $(BUILD) measure

# Time per view, split between the simulated capture and the firmware's processing.
$(BUILD)/bench_view: $(BUILD)/bench/bench_view.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(BOARD_LIBS)
# Fusion beside Open3D's ScalableTSDFVolume on the same depth (bench/fusion_open3d.py).
$(BUILD)/bench_fusion: $(BUILD)/bench/bench_fusion.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(BOARD_LIBS)
# Frame encodings side by side (libspng and libzstd only here).
$(BUILD)/bench_frames: $(BUILD)/bench/bench_frames.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CC) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(BOARD_LIBS) -lspng -lzstd
$(BUILD)/bench/bench_frames.o: bench/bench_frames.c | deps
	@pkg-config --exists spng libzstd || scripts/install-deps.sh bench
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests -c $< -o $@
$(BUILD)/bench/%.o: bench/%.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests -c $< -o $@
# The decode benchmark against OpenCV (C++, only here; Debian's libopencv-contrib-dev).
$(BUILD)/bench/opencv_graycode.o: bench/opencv_graycode.cpp
	@pkg-config --exists opencv4 || scripts/install-deps.sh bench
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 -O2 -Wall -Wextra -Werror $(shell $(PKG_CONFIG) --cflags opencv4 2>/dev/null) -c $< -o $@
$(BUILD)/bench_decode: $(BUILD)/bench/bench_decode.o $(BUILD)/bench/opencv_graycode.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CXX) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(shell $(PKG_CONFIG) --libs opencv4 2>/dev/null)
$(BUILD)/bench/bench_decode.o: bench/bench_decode.c | deps
	@pkg-config --exists opencv4 || scripts/install-deps.sh bench
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests -Ibench -c $< -o $@

bench: deps $(BUILD)/bench_view $(BUILD)/bench_decode $(BUILD)/bench_frames $(BUILD)/bench_fusion $(BUILD)/scanner $(BUILD)/mesh-compare
	@/usr/bin/python3 -c 'import open3d' 2>/dev/null || scripts/install-deps.sh bench
	$(BUILD)/bench_decode
	@echo
	$(BUILD)/bench_frames config/sim.ini
	@echo
	$(BUILD)/bench_view config/sim.ini
	@echo
	@bench/static_memory.sh $(BUILD)/libfirmware.a
	@echo
	bench/bench_scan.sh $(BUILD) config/sim.ini
	@echo
	@$(MAKE) --no-print-directory bench-callgrind

# Instruction counts of one view's firmware processing (stable on a noisy machine): compare a
# change with the one before it.
bench-callgrind: deps $(BUILD)/bench_view
	@command -v valgrind >/dev/null || scripts/install-deps.sh bench
	@BENCH_REPEAT=1 valgrind --tool=callgrind --callgrind-out-file=$(BUILD)/callgrind.out \
		--collect-atstart=no --toggle-collect=process_view_once $(BUILD)/bench_view config/sim.ini > /dev/null 2>$(BUILD)/callgrind.log
	@callgrind_annotate $(BUILD)/callgrind.out 2>/dev/null | \
		awk '/PROGRAM TOTALS/ { gsub(",", "", $$1); printf "instructions per view, firmware decode to PLY (callgrind, machine-independent): %.0f million\n\n", $$1 / 1e6 }'
	@callgrind_annotate $(BUILD)/callgrind.out 2>/dev/null | sed -n '/Ir/,/^$$/p' | head -n 30
