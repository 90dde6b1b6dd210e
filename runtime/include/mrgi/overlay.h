#pragma once
/// @file
/// The composite as an overlay for see-through and passthrough headsets: an image a compositor
/// blends over its own passthrough video instead of showing mrgi's composited camera frame.
///
/// The blend (premultiplied alpha "over", in linear light):
///
///     shown = overlay.rgb + (1 - overlay.a) x passthrough
///
/// with overlay.rgb sRGB-encoded (sample the image as an _SRGB format, or decode it) and
/// overlay.a linear; in Vulkan: an R8G8B8A8_SRGB image, colour blend ONE, ONE_MINUS_SRC_ALPHA,
/// into a target that blends in linear light (an _SRGB attachment). blend_overlay() is the same
/// equation on the CPU.
///
/// How each pixel is encoded, from the composite o and the camera frame c (linear, per channel):
///   - a virtual pixel: rgb = o, a = 1 (the object covers the passthrough);
///   - a real pixel: k = min over the channels of o / c, clamped to [0, 1] (1 where the camera
///     is black: nothing to darken), a = 1 - k, rgb = o - k c. Over the camera frame itself the
///     blend gives k c + (o - k c) = o exactly (to the 8-bit steps): a shadow is the alpha's
///     darkening, light the objects add (bounce, caustics) is the additive part, and a change
///     of colour is both (the darkening of the channel that darkens most, the rest added back).
///
/// What it cannot express: the additive part is computed against mrgi's camera frame, so over
/// a passthrough that differs from it (another exposure, white balance or latency) a darkening
/// still scales the passthrough (right), but the colour added back where channels darken
/// unequally, and any added light, stay as they were computed (an absolute amount, not a
/// ratio of the passthrough); and a see-through display (optical, additive) cannot darken at
/// all: there only rgb shows.
#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/image.h"

namespace mrgi {

/// The overlay of a composite (FrameOutput::image, its alpha ignored) over the camera frame it
/// was composed from (InputFrame::color at the output's size), with FrameOutput::virtual_mask
/// (255 virtual). BadUsage naming the image whose size differs from the composite's.
MRGI_API Expected<ImageRGBA8> make_overlay(const ImageRGBA8& composite, const ImageU8& virtual_mask,
                                           const ImageRGB8& camera);

/// The compositor's blend on the CPU: the overlay over `passthrough` (sRGB-encoded), in linear
/// light, re-encoded to sRGB 8-bit. BadUsage where the sizes differ.
MRGI_API Expected<ImageRGB8> blend_overlay(const ImageRGBA8& overlay, const ImageRGB8& passthrough);

}  // namespace mrgi
