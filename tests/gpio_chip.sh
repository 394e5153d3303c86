#!/bin/sh
# The GPIO backend against a real kernel GPIO chip: the arm64 appliance scanner in a virtual
# machine (qemu-system-aarch64, machine "virt", whose PL061 GPIO controller Debian's arm64
# kernel drives), where gpioset holds one of the scanner's lines as another program would.
# Checks: with every line free the selftest requests them all; with one held it names the line
# and its holder; afterwards the kernel shows no line left requested by the scanner. Three times:
# the default build on a 1 GB machine (where the LIMITS=large build cannot start), the
# LIMITS=small build on a 512 MB one (where the default build cannot start), the LIMITS=large
# build on a 2 GB one. Run by `make test-gpio-chip`, which cross-builds the three.
# The same VM (default build) loads vivid, the kernel's virtual video driver, and runs the V4L2
# backend on it (tools/vivid_capture.c: format, the mmap ring, drop_frames, frame timestamps,
# binning, a timeout when frames stop) and the selftest with it as the rig's camera; and it has
# a virtio-gpu display, on which the HDMI projector backend steps through the pattern sequence
# (tools/drm_show.c) while this script takes qemu's screendump of each pattern on screen and
# compares it with the pattern.
# Ends with cmocka's summary lines so that tests/run.sh counts it.
set -eu
cd "$(dirname "$0")/.."
SCANNER=${SCANNER:-build/aarch64-linux-gnu/linux/scanner}
SCANNER_SMALL=${SCANNER_SMALL:-build/aarch64-linux-gnu/small/linux/scanner}
SCANNER_LARGE=${SCANNER_LARGE:-build/aarch64-linux-gnu/large/linux/scanner}
SECCOMP_RUN=${SECCOMP_RUN:-build/aarch64-linux-gnu/linux/seccomp-run}
VIVID_CAPTURE=${VIVID_CAPTURE:-build/aarch64-linux-gnu/linux/vivid-capture}
DRM_SHOW=${DRM_SHOW:-build/aarch64-linux-gnu/linux/drm-show}
WORK=${WORK:-build/gpio-chip}
TRIPLET=aarch64-linux-gnu
for tool in qemu-system-aarch64 cpio "$TRIPLET-readelf"; do
    command -v "$tool" >/dev/null || { echo "gpio_chip: $tool missing (make test-gpio-chip installs it)"; exit 1; }
done
rm -rf "$WORK/root" "$WORK"/vm-*.log
mkdir -p "$WORK/debs" "$WORK/root"

# Debian's arm64 kernel, static busybox and the gpiod tools, unpacked (not installed).
fetch() { # package name, as apt-get download takes it
    ls "$WORK/debs/$2"_*.deb >/dev/null 2>&1 && return 0
    (cd "$WORK/debs" && apt-get download "$1" >/dev/null 2>&1) ||
        { apt-get update -qq && (cd "$WORK/debs" && apt-get download "$1" >/dev/null); }
}
kernel=$(apt-cache depends linux-image-arm64:arm64 | sed -n 's/.*Depends: \(linux-image-[^:]*\).*/\1/p' | head -n 1)
fetch "$kernel:arm64" "$kernel"
fetch busybox-static:arm64 busybox-static
fetch gpiod:arm64 gpiod
# udevadm, to run the installed GPIO rule on the kernel's own chip, and what it links to.
for p in udev libsystemd-shared libkmod2 libacl1 libblkid1 libcap2 libselinux1 libcrypt1 \
    libgcrypt20 libgpg-error0 libip4tc2 liblz4-1 libmount1 libssl3 libpam0g libzstd1 liblzma5 \
    libpcre2-8-0 libaudit1 libcap-ng0; do
    fetch "$p:arm64" "$p"
done
rm -rf "$WORK/unpacked" && mkdir -p "$WORK/unpacked"
for d in "$WORK"/debs/*.deb; do dpkg-deb -x "$d" "$WORK/unpacked"; done
IMAGE=$(ls "$WORK"/unpacked/boot/vmlinuz-* | head -n 1)

# The initramfs: busybox, the scanner and gpiod's tools with the shared libraries they need.
R=$WORK/root
mkdir -p "$R/bin" "$R/lib/$TRIPLET" "$R/etc/scanner" "$R/proc" "$R/sys" "$R/dev" "$R/tmp" \
    "$R/run" "$R/etc/udev/rules.d" "$R/usr/lib/$TRIPLET/systemd"
cp "$WORK/unpacked/bin/busybox" "$R/bin/"
cp "$SCANNER" "$R/bin/scanner-default"
cp "$SCANNER_SMALL" "$R/bin/scanner-small"
cp "$SCANNER_LARGE" "$R/bin/scanner-large"
cp "$WORK/unpacked/usr/bin/gpioset" "$WORK/unpacked/usr/bin/gpioinfo" "$R/bin/"
cp "$VIVID_CAPTURE" "$R/bin/vivid-capture"
cp "$DRM_SHOW" "$R/bin/drm-show"
# vivid and the modules it needs, in an order that loads each after what it depends on (the
# package ships no modules.dep: each module names its own in its .modinfo).
MODDIR=$(ls -d "$WORK"/unpacked/lib/modules/* | head -n 1)
mkdir -p "$R/lib/modules"
: > "$R/lib/modules/order"
add_module() { # module name, as depends= writes it
    f=$(find "$MODDIR" -name "$1.ko" -o -name "$(echo "$1" | tr _ -).ko" | head -n 1)
    [ -n "$f" ] || { echo "gpio_chip: no kernel module $1" >&2; exit 1; }
    # sh has no local variables but the positional ones: $2 the file's name, $3 its dependencies
    set -- "$1" "$(basename "$f" .ko)" "$(strings "$f" | sed -n 's/^depends=//p' | tr , ' ')"
    grep -qx "$2" "$R/lib/modules/order" && return 0
    cp "$f" "$R/lib/modules/"
    for dep in $3; do add_module "$dep"; done
    echo "$2" >> "$R/lib/modules/order"
}
add_module vivid
add_module virtio_pci
add_module virtio-gpu
# The installed unit's system-call filter, and a runner that enforces it (tools/seccomp_run.c).
cp "$SECCOMP_RUN" "$R/bin/seccomp-run"
scripts/syscall-list.sh config/deploy/scanner@.service > "$R/etc/scanner/syscalls"
libdirs="/usr/lib/$TRIPLET /lib/$TRIPLET $WORK/unpacked/usr/lib/$TRIPLET $WORK/unpacked/lib/$TRIPLET"
cp "$WORK/unpacked/bin/udevadm" "$R/bin/"
cp -L "$WORK"/unpacked/usr/lib/$TRIPLET/systemd/libsystemd-shared-*.so "$R/usr/lib/$TRIPLET/systemd/"
# The installed rule as it is, and the same rule with this board's chip (the PL061) added, as a
# person with another board would.
cp config/deploy/60-scanner-gpio.rules "$R/etc/scanner/"
sed 's/|raspberrypi,rp1-gpio"/|raspberrypi,rp1-gpio|arm,pl061"/' config/deploy/60-scanner-gpio.rules \
    > "$R/etc/scanner/60-scanner-gpio-pl061.rules"
printf 'root:x:0:\ngpio:x:997:\n' > "$R/etc/group"
copy_libs() { # every library an ELF needs, recursively
    for lib in $("$TRIPLET-readelf" -d "$1" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p'); do
        [ -e "$R/lib/$TRIPLET/$lib" ] && continue
    [ -e "$R/usr/lib/$TRIPLET/systemd/$lib" ] && continue
        for d in $libdirs; do
            if [ -e "$d/$lib" ]; then
                cp -L "$d/$lib" "$R/lib/$TRIPLET/$lib"
                copy_libs "$R/lib/$TRIPLET/$lib"
                break
            fi
        done
        [ -e "$R/lib/$TRIPLET/$lib" ] || { echo "gpio_chip: no $lib for $1" >&2; exit 1; }
    done
}
for elf in "$R/bin/scanner-default" "$R/bin/scanner-small" "$R/bin/scanner-large" \
    "$R/bin/gpioset" "$R/bin/gpioinfo" \
    "$R/bin/seccomp-run" "$R/bin/udevadm" "$R/bin/vivid-capture" "$R/bin/drm-show" \
    "$R"/usr/lib/$TRIPLET/systemd/libsystemd-shared-*.so; do
    copy_libs "$elf"
done
cp -L "/usr/lib/$TRIPLET/ld-linux-aarch64.so.1" "$R/lib/ld-linux-aarch64.so.1"

# The rig's config with the PL061's eight lines: projector on 0..2, lights on 4..7 (line 3 is
# the board's power button in the device tree).
sed -e 's/^chip = .*/chip = gpiochip0/' -e 's/^projector_enable = .*/projector_enable = 0/' \
    -e 's/^projector_trigger = .*/projector_trigger = 1/' \
    -e 's/^projector_reset = .*/projector_reset = 2/' -e 's/^light_0 = .*/light_0 = 4/' \
    -e 's/^light_1 = .*/light_1 = 5/' -e 's/^light_2 = .*/light_2 = 6/' \
    -e 's/^light_3 = .*/light_3 = 7/' config/pi-v4l2.ini > "$R/etc/scanner/rig.ini"

# The checks run the build named on the kernel command line (scanner=default, small or large);
# the default and large builds' --version show whether they can start with this much memory.
cat > "$R/init" <<'EOF'
#!/bin/busybox sh
/bin/busybox --install -s /bin
mount -t proc proc /proc; mount -t sysfs sys /sys; mount -t devtmpfs dev /dev
build=$(sed -n 's/.*scanner=\([a-z]*\).*/\1/p' /proc/cmdline)
ln -s /bin/scanner-$build /bin/scanner
echo "== default build starts"; scanner-default --version 2>&1; echo "exit $?"
echo "== large build starts"; scanner-large --version 2>&1; echo "exit $?"
echo "== gpioinfo"; gpioinfo
udev() { # the rule file to run on the chip
    rm -f /etc/udev/rules.d/*; cp "$1" /etc/udev/rules.d/
    udevadm test --action=add /sys/bus/gpio/devices/gpiochip0 2>&1 |
        grep -E 'Reading rules file|Setting permissions'
}
echo "== udev, the installed rule"; udev /etc/scanner/60-scanner-gpio.rules
echo "== udev, the rule with this board's chip"; udev /etc/scanner/60-scanner-gpio-pl061.rules
echo "== selftest, lines free"; scanner selftest --config /etc/scanner/rig.ini 2>&1
echo "== selftest under the unit's system-call filter"
seccomp-run /etc/scanner/syscalls -- scanner selftest --config /etc/scanner/rig.ini 2>&1
echo "exit $?"
gpioset --mode=signal gpiochip0 6=1 & holder=$!
sleep 1
echo "== selftest, line 6 held"; scanner selftest --config /etc/scanner/rig.ini 2>&1
echo "== gpioinfo after"; gpioinfo
kill $holder
if [ "$build" = default ]; then
    echo "== vivid"
    for m in $(cat /lib/modules/order); do insmod /lib/modules/$m.ko || echo "insmod $m failed"; done
    for d in /sys/class/video4linux/video*; do
        grep -q 'vid-cap' "$d/name" 2>/dev/null && dev=/dev/${d##*/} && break
    done
    echo "capture node ${dev:-none}"
    echo "== vivid capture"; vivid-capture "$dev" 2>&1
    echo "== selftest, vivid as the camera"
    sed "/^\[camera\]/,/^\[/ s|^device = .*|device = $dev|" /etc/scanner/rig.ini > /tmp/vivid.ini
    scanner selftest --config /tmp/vivid.ini 2>&1
    echo "== display"; ls /dev/dri
    echo "== drm show"; drm-show /dev/dri/card0 2>&1
fi
echo "== done"
poweroff -f
EOF
chmod +x "$R/init"
(cd "$R" && find . | cpio -o -H newc --quiet | gzip -1) > "$WORK/initramfs.gz"

passed=0
failed=0
check() { # name, section, then patterns the section must (or, with !, must not) show
    name=$1
    section=$2
    shift 2
    body=$(awk -v s="== $section" '$0 == s {on = 1; next} /^== / {on = 0} on' "$log")
    ok=1
    for pat in "$@"; do
        case $pat in
        !*) printf '%s\n' "$body" | grep -qE -- "${pat#!}" && ok=0 ;;
        *) printf '%s\n' "$body" | grep -qE -- "$pat" || ok=0 ;;
        esac
    done
    if [ $ok -eq 1 ]; then
        echo "[       OK ] gpio_chip ($vm): $name"
        passed=$((passed + 1))
    else
        echo "[  FAILED  ] gpio_chip ($vm): $name"
        printf '%s\n' "$body" | sed 's/^/    /'
        failed=$((failed + 1))
    fi
}

# Each "shown pattern N" the VM prints: qemu's screendump of the display, through its monitor
# (the log is read as it grows; this runs beside qemu and is killed when it ends).
screendumps() {
    seen=0
    while :; do
        lines=$(wc -l < "$log")
        while [ "$seen" -lt "$lines" ]; do
            seen=$((seen + 1))
            line=$(sed -n "${seen}p" "$log")
            case $line in
            "shown "*)
                set -- $line
                echo "screendump $WORK/shot-$2-$3.ppm" |
                    socat - "UNIX-CONNECT:$WORK/monitor.sock" >/dev/null 2>&1 ;;
            esac
        done
        sleep 0.2
    done
}

boot() { # memory in MB, the build the checks run
    vm="$2 build, $1 MB"
    log=$WORK/vm-$2.log
    rm -f "$WORK"/shot-*.ppm "$WORK/monitor.sock"
    : > "$log"
    screendumps & watcher=$!
    timeout 600 qemu-system-aarch64 -M virt -cpu cortex-a57 -m "$1" -nographic -no-reboot \
        -nic none -device virtio-gpu-pci -monitor "unix:$WORK/monitor.sock,server,nowait" \
        -kernel "$IMAGE" -initrd "$WORK/initramfs.gz" \
        -append "console=ttyAMA0 panic=-1 quiet scanner=$2" 2>&1 | stdbuf -oL tr -d '\r' > "$log" || true
    kill "$watcher" 2>/dev/null || true
    wait "$watcher" 2>/dev/null || true
    check "the VM found the PL061 chip" "gpioinfo" "^gpiochip0 - 8 lines"
    check "the installed udev rule leaves another board's chip alone" \
        "udev, the installed rule" "Reading rules file: .*60-scanner-gpio.rules" \
        "!Setting permissions"
    check "with the board's chip added, the rule gives it to the gpio group" \
        "udev, the rule with this board's chip" "/dev/gpiochip0, uid=0, gid=997, mode=0660"
    check "every line free: all requested" "selftest, lines free" \
        "^gpio +gpiochip0 +ok +7 lines requested and driven low"
    check "the selftest under the unit's system-call filter" \
        "selftest under the unit's system-call filter" \
        "^gpio +gpiochip0 +ok +7 lines requested and driven low" "^exit 1$"
    check "a held line: named, with its holder" "selftest, line 6 held" \
        "^gpio +gpiochip0 +MISSING +gpio: light_2: cannot request gpiochip0 line 6, in use by gpioset: Device or resource busy"
    check "nothing left requested by the scanner" "gpioinfo after" \
        'line +6: +unnamed +"gpioset" +output' '!"scanner"'
    if ! grep -q "^== done" "$log"; then
        echo "[  FAILED  ] gpio_chip ($vm): the VM did not finish (see $log)"
        failed=$((failed + 1))
    fi
}

boot 1024 default
check "the default build starts" "default build starts" "^scanner .*HAL=linux" "^exit 0$"
check "the LIMITS=large build cannot start" "large build starts" "!^scanner .*HAL=linux" "!^exit 0$"
check "vivid loads and makes a capture node" "vivid" "^capture node /dev/video[0-9]+$" "!failed"
check "V4L2 on vivid: format negotiated, streaming" "vivid capture" "^open 640x480 yuyv: ok$" \
    "^frame 5: 640x480 sequence"
check "V4L2 on vivid: no exposure control, its own used, others refused" "vivid capture" \
    "no exposure control; its own fixed exposure is used" "^other exposure: refused"
check "V4L2 on vivid: queued frames and drop_frames skipped, timestamps, the picture" \
    "vivid capture" "^frames: 6, smallest sequence step ([3-9]|[1-9][0-9]+) \(drop_frames 2\), timestamps ok, test pattern seen$"
check "V4L2 on vivid: a 1280x720 sensor binned 2x2" "vivid capture" \
    "^open 1280x720 binned to 640x360: ok$" "^binned frame: ok 640x360$"
check "V4L2 on vivid: a timeout when frames stop" "vivid capture" \
    "^no frames \(control set\): timed out after [0-9]+ ms$" "^done$"
check "virtio-gpu makes a DRM device" "display" "^card0"
check "the HDMI projector: 1024x768 taken, the whole sequence stepped" "drm show" \
    "^open 1024x768: ok$" "^sequence: ok \(22 patterns\)$" "^done$"
shots=$(/usr/bin/python3 tools/drm_screendumps.py "$WORK" 2>&1)
printf '%s\n' "$shots" | sed 's/^/    /'
for name in "pattern 0" "pattern 1" "pattern 2" "pattern 3" "pattern 12" "pattern 21" "off 0"; do
    if printf '%s\n' "$shots" | grep -q "^$name: 1024x768, 0 pixels differ"; then
        echo "[       OK ] gpio_chip ($vm): the display shows $name"
        passed=$((passed + 1))
    else
        echo "[  FAILED  ] gpio_chip ($vm): the display shows $name"
        failed=$((failed + 1))
    fi
done
check "the selftest with vivid as the camera" "selftest, vivid as the camera" \
    "^camera +/dev/video[0-9]+ +ok +v4l2 frame 1280x720" "!^turntable +/dev/video"
# 512 MB: the default build's 633 MiB of static buffers do not fit; LIMITS=small's do.
boot 512 small
check "the default build cannot start" "default build starts" "!^scanner .*HAL=linux" "!^exit 0$"
# 2 GB: the LIMITS=large build's 1.8 GB (16 MP frames; its colour frames in the fusion
# volume's memory) fit.
boot 2048 large
check "the LIMITS=large build starts" "large build starts" "^scanner .*HAL=linux" "^exit 0$"
if [ $failed -eq 0 ]; then echo "[  PASSED  ] $passed test(s)."; else echo "[  FAILED  ] $failed test(s)."; fi
[ $failed -eq 0 ]
