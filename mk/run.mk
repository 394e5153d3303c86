# Running and looking after the tree: a simulated scan, the web page, the browser test, the
# generated docs, make help, formatting.

## run: a simulated scan of the bunny with config/sim.ini into a new folder of scans/sim
run: deps $(BUILD)/scanner
	$(BUILD)/scanner scan --config config/sim.ini

# The web interface on the simulator (docs/web.md): http://127.0.0.1:8080, Ctrl-C ends it. A
# second make, so that civetweb, if deps just installed it, is seen.
## serve: the web interface on the simulator at http://127.0.0.1:8080
serve: deps
	@$(MAKE) --no-print-directory $(BUILD)/scanner $(BUILD)/scanner-web $(BUILD)/mesh-compare $(CALIB_TOOL)
	@echo "make serve: the scanner's page is at http://127.0.0.1:8080 (Ctrl-C ends it)"
	$(BUILD)/scanner serve --config config/sim.ini --config config/sim-glossy.ini --listen 127.0.0.1:8080

# The page and its API in Debian's Chromium (tests/browser/browser_test.mjs, about 90 s; in CI).
# The pictures it takes of the page are in $(BUILD)/browser/ (docs/web/ has a pair).
## test-browser: the page in a real headless Chromium (about 90 s)
test-browser: deps
	@command -v chromium >/dev/null 2>&1 || scripts/install-deps.sh browser
	@scripts/install-deps.sh node
	@test -f tests/browser/node_modules/playwright-core/package.json || \
		npm ci --prefix tests/browser --no-audit --no-fund --loglevel=error
	@$(MAKE) --no-print-directory $(BUILD)/scanner $(BUILD)/scanner-web $(BUILD)/mesh-compare $(CALIB_TOOL)
	node tests/browser/browser_test.mjs $(BUILD)

# Blender 3.4 (Debian's, installed if missing; not in CI: 66 packages) imports a scan's
# mesh.ply, mesh.obj, mesh.stl and mesh.glb upright and at the object's size in a millimetre scene.
## check-blender: Blender imports a simulated scan's four meshes (not in CI)
check-blender: deps $(BUILD)/scanner
	@scripts/install-deps.sh blender
	@rm -rf $(BUILD)/blender-scan
	$(BUILD)/scanner scan --config config/sim.ini --out $(BUILD)/blender-scan > /dev/null
	@blender -b --python-exit-code 1 -P tests/blender_import.py -- $(BUILD)/blender-scan 150 \
		> $(BUILD)/blender.log 2>&1 || { cat $(BUILD)/blender.log; exit 1; }
	@grep '^blender:' $(BUILD)/blender.log
	@rm -rf $(BUILD)/blender-scan

# The bunny in two passes (upright, then on its side), one model: scans/sim-complete/latest/.
## run-complete: the bunny in two passes, upright then on its side, and its distance to the truth
run-complete: deps $(BUILD)/scanner $(BUILD)/mesh-compare
	$(BUILD)/scanner scan --config config/sim-complete.ini
	$(BUILD)/mesh-compare --align scans/sim-complete/latest/mesh.ply scans/sim-complete/latest/truth_mesh.ply

## docs: docs/config.md from the config key tables
docs: $(BUILD)/scanner
	$(BUILD)/scanner config-doc > docs/config.md

# docs/errors.md: bad inputs and the messages they get (tests/cli.sh checks it is current).
## errors-doc: docs/errors.md: bad inputs tried and the message each gets
errors-doc: deps $(BUILD)/scanner linux-build
	scripts/errors-table.sh $(BUILD) > docs/errors.md

## help: this list
help:
	@echo "make TARGET (README.md says more; the build's knobs: HAL=sim|linux, LIMITS=small,"
	@echo "SAN=1, CROSS_COMPILE=aarch64-linux-gnu-, BUILD=DIR)"
	@sed -n 's/^## \([^:]*\): /  \1\t/p' $(filter Makefile mk/%,$(MAKEFILE_LIST)) | expand -t 24

## format-check: every C file as clang-format writes it (make test runs it)
FORMATTED = $$(git ls-files '*.c' '*.h' '*.cpp')
format-check:
	@bad=$$(clang-format --dry-run $(FORMATTED) 2>&1 | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: warning:.*/\1/p' | sort -u); \
		[ -z "$$bad" ] || { printf '  not as clang-format writes it: %s\n' $$bad; \
		echo "format-check: run make format"; exit 1; }
	@echo "format-check: every C file as clang-format writes it"

## format: clang-format every C file
format:
	clang-format -i $(FORMATTED)

## clean: remove build/
clean:
	rm -rf build
