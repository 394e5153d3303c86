# The appliance on arm64: cross-built and its tests under qemu-aarch64, and in a qemu VM on a
# real kernel GPIO chip.

# arm64 (a Raspberry Pi 4 or 5 on a 64-bit OS): the appliance's scanner cross-built and checked
# to be an AArch64 ELF, then every cmocka unit test built for arm64 and run under qemu-aarch64
# (Debian's qemu-user; the arm64 loader and libraries come with the multiarch -dev packages).
ARM64 := CROSS_COMPILE=aarch64-linux-gnu-
# Emulated, the tests that render whole simulated scans take many minutes each: test-arm64 runs
# the others (every firmware algorithm, config, Modbus, backends); test-arm64-full runs them all.
ARM64_SLOW := test_colour test_nomalloc test_ply test_safety test_scan test_scan_faults test_sim test_view
ARM64_TESTS = $(filter-out $(addprefix $(BUILD)/tests/,$(ARM64_SLOW)),$(TEST_BIN))
## test-arm64: the appliance cross-built for arm64 and the unit tests under qemu-aarch64
test-arm64:
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux deps
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux arm64-check-elf
	@$(MAKE) --no-print-directory $(ARM64) HAL=sim arm64-run-tests
## test-arm64-full: every unit test under qemu-aarch64 (slow)
test-arm64-full:
	@$(MAKE) --no-print-directory $(ARM64) HAL=sim deps
	@$(MAKE) --no-print-directory $(ARM64) HAL=sim ARM64_SLOW= arm64-run-tests
# The GPIO backend against a real kernel GPIO chip (the PL061 of qemu's arm64 "virt" machine),
# with another program holding one of the lines; the default build on 1 GB, the LIMITS=small
# build on 512 MB: tests/gpio_chip.sh. About two minutes.
## test-gpio-chip: the arm64 scanner in a qemu VM on a real kernel GPIO chip, vivid and virtio-gpu
test-gpio-chip:
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux deps
	@{ command -v qemu-system-aarch64 && command -v cpio && command -v systemd-analyze && command -v socat; } >/dev/null 2>&1 || scripts/install-deps.sh gpio-chip
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux all
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux LIMITS=small all
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux LIMITS=large all
	@$(MAKE) --no-print-directory $(ARM64) HAL=linux seccomp-tool vivid-tool
	@tests/run.sh tests/gpio_chip.sh
arm64-check-elf: $(BUILD)/scanner
	@$(CROSS_COMPILE)readelf -h $< | grep -q 'Machine: *AArch64' && echo "$<: AArch64 ELF"
arm64-run-tests: $(TEST_BIN)
	@RUN_WITH=qemu-aarch64 BUILD=$(BUILD) tests/run.sh $(ARM64_TESTS)
