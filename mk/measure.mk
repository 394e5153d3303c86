# Measuring: one view against the truth, the colour evaluation, full scans, the calibration
# demo, the benchmarks. Numbers for the notes; none of it is in make test.

# Decoding rate, depth error and time per view on the simulator (numbers for the notes).
$(BUILD)/measure_view: $(BUILD)/tools/measure_view.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON) $(BOARD_LIBS)
## measure: one view against the simulator's truth: decoding, depth, normals, time
measure: deps $(BUILD)/measure_view
	$(BUILD)/measure_view config/sim.ini config/sim-limit.ini config/sim-glossy.ini config/sim-concave.ini
## measure-inverse: make measure with inverses for the finest 4, 3, 2 bits only, side by side (6 min)
measure-inverse: deps $(BUILD)/measure_view
	/usr/bin/python3 scripts/measure-inverse.py $(BUILD)

# Intrinsic colour (issue 4): Jost et al.'s comparison reproduced on the simulator, written to
# docs/colour-eval/ (table as Markdown and CSV, close-up PNGs of a view boundary). About 20 minutes.
EVAL_DIR ?= docs/colour-eval
## eval-texture: the texture atlas against the vertex colours and the truth, docs/colour-eval/texture-eval.md (about 5 min)
eval-texture: deps $(BUILD)/scanner $(BUILD)/texture-eval
	tools/texture_eval.sh $(BUILD) $(EVAL_DIR)

## eval-cycles: the colour eval through Blender's Cycles, docs/colour-eval/cycles-eval.md (about 15 min; not in CI)
eval-cycles: deps $(BUILD)/scanner $(BUILD)/texture-eval $(BUILD)/mesh-compare
	@scripts/install-deps.sh blender
	tools/cycles_eval.sh $(BUILD) $(EVAL_DIR)

## eval: intrinsic colour compared on the simulator into docs/colour-eval/ (about 25 min)
# EVAL_SCENES: some of tests/eval/'s scenes only (.ci/run: two, to see it run end to end).
eval: deps $(BUILD)/scanner $(BUILD)/colour-eval $(BUILD)/relight-eval
	tools/colour_eval.sh $(BUILD) $(EVAL_DIR) $(EVAL_SCENES)

# Full simulated scans measured against the true surface, with a turntable that misses its
# angle by up to 1 and 2 degrees (each view's angle as reported, registered and true), and peak
# memory for 8 and 24 views.
## measure-objects: the object corpus at every view count, table error and slip, one table (long)
measure-objects: deps $(BUILD)/scanner $(BUILD)/mesh-compare
	@command -v openscad >/dev/null 2>&1 || scripts/install-deps.sh objects
	scripts/measure-objects.sh $(BUILD)
## measure-scan: full scans against the true surface; the registration's targets (long)
measure-scan: deps $(BUILD)/scanner $(BUILD)/mesh-compare $(BUILD)/measure-registration
	scripts/measure-scan.sh $(BUILD)

# MeshLab opens a scan's mesh (installs MeshLab and Xvfb when missing: large, so not in test).
## interop-meshlab: MeshLab opens a scan's mesh
interop-meshlab: deps $(BUILD)/scanner
	rm -rf $(BUILD)/meshlab-scan
	$(BUILD)/scanner scan --config config/sim.ini --out $(BUILD)/meshlab-scan > /dev/null
	tests/interop_meshlab.sh $(BUILD)/meshlab-scan

# Each view's angle as reported, as registered and as true (tools/measure_registration.c).
$(BUILD)/measure-registration: $(call obj,tools/measure_registration.c $(CONFIG_SRC) $(SCAN_DIR_SRC) hal/posix/image_io.c) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON)

# The calibration's accuracy (tools/measure_calib.c): a calibration against the true rig.
$(BUILD)/measure-calib: $(call obj,tools/measure_calib.c $(CONFIG_SRC)) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON)

# Calibration of the simulated demo rig from scratch (scans/calib-demo/), and how close it is:
# make calibrate-demo prints the table parameter | true | nominal | recovered | error and scans
# the bunny with the result; make measure-calib also scans with the true and the nominal file.
# A few minutes each (docs/calibration.md).
## calibrate-demo: calibrate the simulated demo rig from scratch and scan with the result
calibrate-demo: deps $(BUILD)/scanner $(BUILD)/scanner-calibrate $(BUILD)/mesh-compare $(BUILD)/measure-calib
	scripts/measure-calib.sh $(BUILD)
## measure-calib: calibrate-demo, and scans with the true, nominal and pinhole calibrations
measure-calib: deps $(BUILD)/scanner $(BUILD)/scanner-calibrate $(BUILD)/mesh-compare $(BUILD)/measure-calib
	scripts/measure-calib.sh $(BUILD) measure
## measure-calib-advice: a weak 5-board calibration, its advice followed (--add), before and after
measure-calib-advice: deps $(BUILD)/scanner $(BUILD)/scanner-calibrate $(BUILD)/mesh-compare
	scripts/measure-calib-advice.sh $(BUILD)
## measure-calib-sigma: reported calibration sigma against the spread over 10 noise seeds (long)
measure-calib-sigma: deps $(BUILD)/scanner $(BUILD)/scanner-calibrate
	scripts/measure-calib-sigma.sh $(BUILD)

# Time per view, split between the simulated capture and the firmware's processing.
$(BUILD)/bench_view: $(BUILD)/bench/bench_view.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON) $(BOARD_LIBS)
# One view's processing on 1, 2 and 4 threads.
$(BUILD)/bench_threads: $(BUILD)/bench/bench_threads.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON) $(BOARD_LIBS)
# Fusion beside Open3D's ScalableTSDFVolume on the same depth (bench/fusion_open3d.py).
$(BUILD)/bench_fusion: $(BUILD)/bench/bench_fusion.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON) $(BOARD_LIBS)
# Frame encodings side by side (libspng and libzstd only here).
$(BUILD)/bench_frames: $(BUILD)/bench/bench_frames.o $(BUILD)/tests/test_util.o $(HOST_OBJ) $(BUILD)/libfirmware.a
	$(LINK) $(LDLIBS_COMMON) $(BOARD_LIBS) -lspng -lzstd
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

## measure-large: make run's scan at a DSLR's full 4896 x 3264 by the LIMITS=large build (4 min, 5 GB)
# and the decode against OpenCV at that size; the build is build/large (BUILD=x: x/large).
LARGE_BUILD := $(if $(filter large,$(LIMITS)),$(BUILD),$(BUILD)/large)
measure-large: deps
	@$(MAKE) --no-print-directory LIMITS=large $(LARGE_BUILD)/scanner $(LARGE_BUILD)/mesh-compare $(LARGE_BUILD)/bench_decode
	$(LARGE_BUILD)/bench_decode
	@echo
	scripts/measure-large.sh $(LARGE_BUILD)

## bench: benchmarks: decode against OpenCV, frames, stages, memory, fusion, a whole scan
bench: deps $(BUILD)/bench_view $(BUILD)/bench_threads $(BUILD)/bench_decode $(BUILD)/bench_frames $(BUILD)/bench_fusion $(BUILD)/scanner $(BUILD)/mesh-compare
	@/usr/bin/python3 -c 'import open3d' 2>/dev/null || scripts/install-deps.sh bench
	$(BUILD)/bench_decode
	@echo
	$(BUILD)/bench_frames config/sim.ini
	@echo
	$(BUILD)/bench_view config/sim.ini
	@echo
	$(BUILD)/bench_threads config/sim.ini
	@echo
	@bench/static_memory.sh $(BUILD)/scanner
	@echo
	bench/bench_scan.sh $(BUILD) config/sim.ini
	@echo
	@$(MAKE) --no-print-directory bench-callgrind

# Instruction counts of one view's firmware processing (stable on a noisy machine): compare a
# change with the one before it.
## bench-callgrind: instruction counts of one view under callgrind
bench-callgrind: deps $(BUILD)/bench_view
	@command -v valgrind >/dev/null || scripts/install-deps.sh bench
	@BENCH_REPEAT=1 valgrind --tool=callgrind --callgrind-out-file=$(BUILD)/callgrind.out \
		--collect-atstart=no --toggle-collect=process_view_once $(BUILD)/bench_view config/sim.ini > /dev/null 2>$(BUILD)/callgrind.log
	@callgrind_annotate $(BUILD)/callgrind.out 2>/dev/null | \
		awk '/PROGRAM TOTALS/ { gsub(",", "", $$1); printf "instructions per view, firmware decode to PLY (callgrind, machine-independent): %.0f million\n\n", $$1 / 1e6 }'
	@callgrind_annotate $(BUILD)/callgrind.out 2>/dev/null | sed -n '/Ir/,/^$$/p' | head -n 30
