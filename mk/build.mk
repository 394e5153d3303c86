# Building: the Debian packages a build needs, the compile rules (each layer with its own include
# paths), and the programs: scanner, scanner-calibrate, scanner-web, the simulated turntable and
# the tools.

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
	$(LINK) $(LDLIBS_COMMON) $(BOARD_LIBS)

# OpenCV is installed when the calibration is built on a machine without it (make
# measure-calib-sigma, make calibrate-demo on a fresh machine): before the recipe, whose
# pkg-config --cflags is expanded when it starts.
opencv-deps: deps
	@$(PKG_CONFIG) --exists opencv4 || scripts/install-deps.sh bench
$(BUILD)/calib/calib_cv.o: calib/calib_cv.cpp calib/calib_cv.h | deps opencv-deps
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 -Wall -Wextra -Werror $(OPT) -g -MMD -MP -Icalib $(shell $(PKG_CONFIG) --cflags opencv4 2>/dev/null) -c $< -o $@
$(BUILD)/scanner-calibrate: $(call obj,$(CALIB_SRC)) $(BUILD)/calib/calib_cv.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(CXX) $(LDFLAGS_COMMON) -o $@ $^ $(LDLIBS_COMMON) $(BOARD_LIBS) $(OPENCV_LIBS)

$(BUILD)/web/serve.o: HOST_CFLAGS += -DWEB_WWW_DIR='"$(CURDIR)/web/www"'
$(BUILD)/scanner-web: $(call obj,$(WEB_SRC) app/report.c $(SCAN_DIR_SRC) $(CONFIG_SRC) hal/posix/image_io.c hal/posix/storage_posix.c) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON) -lcivetweb -lcjson

# The simulated controller as its own program, and the client as a command (interop tests).
$(BUILD)/turntable-sim: $(call obj,host_sim/turntable_sim_main.c host_sim/tt_server.c host_sim/tt_ctrl.c)
	$(LINK) $(LDLIBS_COMMON)
$(BUILD)/tt-client: $(call obj,tools/tt_client_main.c hal/modbus/turntable_modbus.c hal/posix/clock_posix.c) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON)

# Runs a command under a system-call allow-list as the systemd unit's filter does (tests only).
$(BUILD)/seccomp-run: tools/seccomp_run.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(WARN) $(OPT) -g -o $@ $< $(shell $(PKG_CONFIG) --libs libseccomp 2>/dev/null)
seccomp-tool: $(BUILD)/seccomp-run
# The V4L2 backend against vivid in the arm64 VM (tests/gpio_chip.sh); HAL=linux builds.
$(BUILD)/vivid-capture: $(call obj,tools/vivid_capture.c hal/linux/camera_v4l2.c hal/linux/v4l2_frame.c) $(BUILD)/libfirmware.a
	$(LINK) -lm
vivid-tool: $(BUILD)/vivid-capture $(BUILD)/drm-show
# The HDMI projector against virtio-gpu in the same VM.
$(BUILD)/drm-show: $(call obj,tools/drm_show.c board/board_display.c hal/linux/projector_drm.c) $(BUILD)/libfirmware.a
	$(LINK) $(shell $(PKG_CONFIG) --libs libdrm) -lm

$(BUILD)/mesh-compare: $(call obj,tools/mesh_compare.c tests/mesh_compare_lib.c host_sim/sim_bvh.c host_sim/sim_mesh.c host_sim/sim_ply_read.c $(CONFIG_SRC) $(SCAN_DIR_SRC) hal/posix/image_io.c) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON)

EVAL_SIM_SRC := tests/colour_metrics.c host_sim/sim_bvh.c host_sim/sim_mesh.c host_sim/sim_ply_read.c host_sim/sim_rig.c host_sim/sim_albedo_image.c board/board_albedo.c host_sim/sim_jpeg.c host_sim/sim_target.c host_sim/sim_material.c $(CONFIG_SRC) $(SCAN_DIR_SRC) hal/posix/image_io.c hal/posix/storage_posix.c
$(BUILD)/colour-eval: $(call obj,tools/colour_eval.c $(EVAL_SIM_SRC)) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON)
$(BUILD)/relight-eval: $(call obj,tools/relight_eval.c $(EVAL_SIM_SRC)) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON)
$(BUILD)/texture-eval: $(call obj,tools/texture_eval.c $(EVAL_SIM_SRC)) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON)
