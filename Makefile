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
# Under the sanitizers at -O2 too: every check stays, and the simulated scans of make test SAN=1
# (the longest part of CI) run a third faster than at -O1 (a sim scan 37 s against 57 s).
ifeq ($(SAN),1)
BUILD := $(BUILD)/san
OPT := -O2 -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
endif
# Compile-time limits (hal/include/hal_limits.h): default, small for a board with 512 MB, or
# large for full-resolution frames on a computer with memory to spare. Every object depends on
# them, so each set builds in its own directory.
LIMITS ?= default
ifeq ($(LIMITS),small)
BUILD := $(BUILD)/small
LIMITS_CFLAGS := -DHAL_LIMITS_SMALL
else ifeq ($(LIMITS),large)
BUILD := $(BUILD)/large
# static buffers near 2 GB: x86-64's medium code model puts them beyond the code's reach (the
# target's, so not for a cross build to arm64, whose small model reaches 4 GB)
LIMITS_CFLAGS := -DHAL_LIMITS_LARGE $(if $(filter x86_64-%,$(shell $(CC) -dumpmachine)),-mcmodel=medium,)
else ifneq ($(LIMITS),default)
$(error LIMITS must be default, small or large, not '$(LIMITS)')
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
# The calibration (scanner-calibrate) sits on app/: it scans with its code; nothing sees it.
INC_calib := -Icalib $(INC_app)
# The web server: the report's pictures and the config's reader from app/ (config.h names the
# board's settings struct); no board code is linked: it never touches a device.
INC_web := -Iweb -Iapp -Iboard -Ifirmware -Ihal/posix -Ihal/modbus -Ihost_sim $(shell $(PKG_CONFIG) --cflags libcjson 2>/dev/null)
# Tests, benchmarks and fuzzers see everything.
ALL_INC := -Ifirmware -Iapp -Iboard -Ihal/posix -Ihal/linux -Ihal/modbus -Ihost_sim
HOST_INC := -Ihal/include $(ALL_INC)
INC_tests := $(ALL_INC)
INC_tests/fuzz := $(ALL_INC)
INC_tools := $(ALL_INC) -Itests
INC_bench := $(ALL_INC)
LAYER_INC = -Ihal/include $(INC_$(patsubst %/,%,$(dir $<)))
HOST_CFLAGS = $(CFLAGS_COMMON) $(LAYER_INC) $(PKG_CFLAGS)
LDFLAGS_COMMON := $(OPT) -g
# Every C program is linked the same way: its objects, then the libraries its rule names.
LINK = $(CC) $(LDFLAGS_COMMON) -o $@ $^
LDLIBS_COMMON = $(PKG_LIBS) -lm

FW_SRC := $(wildcard firmware/*.c) hal/hal.c
POSIX_SRC := $(wildcard hal/posix/*.c) $(wildcard hal/modbus/*.c)
# A config and a calibration read and checked: every program that loads one links these.
CONFIG_SRC := app/config.c app/disk_room.c app/calib_file.c app/ini_schema.c hal/posix/file_posix.c
SCAN_DIR_SRC := app/scan_dir.c app/scan_dir_range.c
APP_LIB_SRC := $(filter app/%,$(CONFIG_SRC)) app/frame_writer.c app/patterns.c app/report.c app/rig.c $(SCAN_DIR_SRC) app/job.c app/job_events.c app/job_live.c app/answer.c app/job_model.c app/job_texture.c app/job_offline.c app/white_cal.c board/board_frame.c
SIM_SRC := $(filter-out host_sim/turntable_sim_main.c,$(wildcard host_sim/*.c)) board/board_sim.c board/board_albedo.c
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
CALIB_SRC := calib/calibrate.c calib/calib_solve.c calib/calib_json.c calib/calib_files.c calib/calib_common.c calib/calib_import.c calib/main.c
OPENCV_LIBS := -lopencv_aruco -lopencv_calib3d -lopencv_imgproc -lopencv_core
CALIB_TOOL := $(if $(HAVE_OPENCV),$(BUILD)/scanner-calibrate,)
# The web interface (scanner serve) is its own program too, scanner-web: civetweb and cJSON
# (Debian's libcivetweb-dev and libcjson-dev, which make installs); a scan never loads them.
# Not cross-built: the board runs the native build's (docs/web.md).
HAVE_CIVETWEB := $(if $(CROSS_COMPILE),,$(shell test -f /usr/include/civetweb.h && $(PKG_CONFIG) --exists libcjson 2>/dev/null && echo 1))
WEB_SRC := web/serve.c web/api.c web/jobs.c web/guard.c web/profiles.c web/calibration.c
WEB_TOOL := $(if $(HAVE_CIVETWEB),$(BUILD)/scanner-web,)
BOARD_LIBS = $(if $(filter linux,$(HAL)),$(shell $(PKG_CONFIG) --libs libgpiod libdrm 2>/dev/null) $(LIBCAMERA_LIBS),)

obj = $(patsubst %.c,$(BUILD)/%.o,$(1))
FW_OBJ := $(call obj,$(FW_SRC))
HOST_OBJ := $(call obj,$(POSIX_SRC) $(APP_LIB_SRC) $(BOARD_SRC)) $(if $(filter linux,$(HAL)),$(LIBCAMERA_OBJ),)
MAIN_OBJ := $(call obj,app/main.c)

.PHONY: help format-check serve test-browser check-blender seccomp-tool vivid-tool all deps opencv-deps test-deps test test-build test-run run-complete linux-build small-build large-build install check-stack size fuzz errors-doc test-arm64 test-arm64-full test-gpio-chip arm64-check-elf arm64-run-tests run clean format docs check-firmware bench measure measure-inverse measure-scan measure-objects measure-large interop-meshlab bench-callgrind eval eval-texture eval-cycles calibrate-demo measure-calib measure-calib-sigma measure-calib-advice
SIM_TOOLS := $(if $(filter sim,$(HAL)),$(BUILD)/turntable-sim $(BUILD)/tt-client $(BUILD)/mesh-compare $(BUILD)/colour-eval $(BUILD)/relight-eval $(BUILD)/texture-eval,)
## all: build/scanner with the simulator, scanner-calibrate and scanner-web where their libraries are (the default)
all: deps $(BUILD)/scanner $(CALIB_TOOL) $(WEB_TOOL) $(SIM_TOOLS)

# The rules, a file each (make help lists every target).
include mk/build.mk mk/test.mk mk/arm64.mk mk/install.mk mk/run.mk mk/measure.mk

.SECONDARY:

-include $(shell find $(BUILD) -name '*.d' -type f 2>/dev/null)
