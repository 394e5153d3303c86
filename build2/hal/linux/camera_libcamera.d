build2/hal/linux/camera_libcamera.o: hal/linux/camera_libcamera.cpp \
 hal/linux/camera_libcamera.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h \
 hal/linux/v4l2_frame.h hal/include/hal_camera.h \
 /usr/include/libcamera/libcamera/libcamera.h \
 /usr/include/libcamera/libcamera/camera.h \
 /usr/include/libcamera/libcamera/base/class.h \
 /usr/include/libcamera/libcamera/base/flags.h \
 /usr/include/libcamera/libcamera/base/object.h \
 /usr/include/libcamera/libcamera/base/bound_method.h \
 /usr/include/libcamera/libcamera/base/signal.h \
 /usr/include/libcamera/libcamera/controls.h \
 /usr/include/libcamera/libcamera/base/span.h \
 /usr/include/libcamera/libcamera/geometry.h \
 /usr/include/libcamera/libcamera/base/compiler.h \
 /usr/include/libcamera/libcamera/request.h \
 /usr/include/libcamera/libcamera/fence.h \
 /usr/include/libcamera/libcamera/base/unique_fd.h \
 /usr/include/libcamera/libcamera/stream.h \
 /usr/include/libcamera/libcamera/color_space.h \
 /usr/include/libcamera/libcamera/framebuffer.h \
 /usr/include/libcamera/libcamera/base/shared_fd.h \
 /usr/include/libcamera/libcamera/pixel_format.h \
 /usr/include/libcamera/libcamera/transform.h \
 /usr/include/libcamera/libcamera/camera_manager.h \
 /usr/include/libcamera/libcamera/control_ids.h \
 /usr/include/libcamera/libcamera/formats.h \
 /usr/include/libcamera/libcamera/framebuffer_allocator.h \
 /usr/include/libcamera/libcamera/logging.h \
 /usr/include/libcamera/libcamera/property_ids.h \
 /usr/include/libcamera/libcamera/version.h
hal/linux/camera_libcamera.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
hal/linux/v4l2_frame.h:
hal/include/hal_camera.h:
/usr/include/libcamera/libcamera/libcamera.h:
/usr/include/libcamera/libcamera/camera.h:
/usr/include/libcamera/libcamera/base/class.h:
/usr/include/libcamera/libcamera/base/flags.h:
/usr/include/libcamera/libcamera/base/object.h:
/usr/include/libcamera/libcamera/base/bound_method.h:
/usr/include/libcamera/libcamera/base/signal.h:
/usr/include/libcamera/libcamera/controls.h:
/usr/include/libcamera/libcamera/base/span.h:
/usr/include/libcamera/libcamera/geometry.h:
/usr/include/libcamera/libcamera/base/compiler.h:
/usr/include/libcamera/libcamera/request.h:
/usr/include/libcamera/libcamera/fence.h:
/usr/include/libcamera/libcamera/base/unique_fd.h:
/usr/include/libcamera/libcamera/stream.h:
/usr/include/libcamera/libcamera/color_space.h:
/usr/include/libcamera/libcamera/framebuffer.h:
/usr/include/libcamera/libcamera/base/shared_fd.h:
/usr/include/libcamera/libcamera/pixel_format.h:
/usr/include/libcamera/libcamera/transform.h:
/usr/include/libcamera/libcamera/camera_manager.h:
/usr/include/libcamera/libcamera/control_ids.h:
/usr/include/libcamera/libcamera/formats.h:
/usr/include/libcamera/libcamera/framebuffer_allocator.h:
/usr/include/libcamera/libcamera/logging.h:
/usr/include/libcamera/libcamera/property_ids.h:
/usr/include/libcamera/libcamera/version.h:
