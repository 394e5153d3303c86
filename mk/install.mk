# The appliance installed, and the other builds make test needs beside the default one.

# The appliance, installed: the HAL=linux scanner, the example configs in /etc/scanner (an edited
# one is kept; the new example goes beside it as .dist), the systemd unit, its user and groups
# (sysusers.d) and the GPIO group rule (udev). DESTDIR stages it (packaging, tests).
PREFIX ?= /usr/local
SYSCONFDIR ?= /etc
UNITDIR ?= /lib/systemd/system
DOCDIR ?= $(PREFIX)/share/doc/scanner
## install: the appliance, its configs, systemd units and web interface (DESTDIR, PREFIX)
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
## linux-build: the appliance build (HAL=linux) beside the simulator build
linux-build: deps
	@$(MAKE) --no-print-directory HAL=linux SAN=$(SAN) $(LINUX_BUILD)/scanner $(if $(HAVE_CIVETWEB),$(LINUX_BUILD)/scanner-web,)
# The simulator build with LIMITS=small (a 512 MB board), for tests/cli.sh.
## small-build: the simulator build with LIMITS=small (a 512 MB board)
small-build: deps
	@$(MAKE) --no-print-directory LIMITS=small SAN=$(SAN) $(BUILD)/small/scanner
# The simulator build with LIMITS=large (full-resolution frames, 3 GB of static buffers), for
# tests/cli.sh; not under the sanitizers (their shadow of 3 GB of buffers is no test of ours).
## large-build: the simulator build with LIMITS=large (4928 x 3456 frames)
large-build: deps
	@$(MAKE) --no-print-directory LIMITS=large $(BUILD)/large/scanner
