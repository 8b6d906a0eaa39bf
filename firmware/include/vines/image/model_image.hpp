// Model images: a built Model<S, N, Dev> as a compact, versioned byte image,
// so that a board never builds its own model (no eigensolver, no matrix
// exponential, no Van Loan blocks on its stack): the host builds it
// (build_model), writes its image (write_image), and the board decodes the
// image chunk by chunk as it arrives straight into its static Model
// (Loader), then steps it as if it had built it.
//
// Image = header (kHeaderBytes, fixed) + body. Everything little-endian,
// written field by field (never a struct copied as bytes):
//   off size field
//    0   4   magic "VNMI"
//    4   2   version (kVersion)
//    6   1   scalar: 0 double, 1 float
//    7   1   sizeof(scalar)
//    8   2   stories N
//   10   1   device kind (DeviceKind: 0 none, 1 tmd, 2 vines)
//   11   1   contact law (ContactLaw) of a VI NES, 0xFF otherwise
//   12   4   total length of the image in bytes (header + body)
//   16   2   field count of the body
//   18   2   reserved, 0
//   20   4   layout check: CRC-32 of the body's field list (each field's wire
//            type and entry count), so a host and a node built from sources
//            whose field lists differ refuse each other's images
//   24   4   CRC-32 (bytes/crc32.hpp) of the whole image but these 4 bytes
// Body: the fields of visit_fields() (image/fields.hpp), in its order, each
// as its raw little-endian entries (double: IEEE-754 binary64 bits, float: binary32;
// bool: one byte 0/1; integers and enums: two's complement of their size);
// matrices column by column (Eigen's storage order).
//
// Padding: the host pads the modal vectors to its SIMD width
// (VINES_MODAL_LANES, see Layout in model.hpp), a board usually does not.
// The image carries the N real modes only (the physical size for the dense
// TMD form), so the body does not depend on the padding; the loader zeroes
// every padding entry (the built model's inert modes hold other
// coefficients, e.g. an identity step, that act on zeros either way).
//
// What is in the body: everything the loop reads (sim.hpp, substep.hpp,
// peaks.hpp, bounce.hpp through the device constants, the energy ledger,
// the outputs floor_displacements/velocities, absolute_accel and
// elastic_energy), and the device's design (TmdDesign, VinesDesign): a few
// doubles, read by absolute_accel (TMD k, c), the divergence guard (sphere
// radius) and host snapshots (the VI NES gap). Left out, reporting only and
// zeroed on load: frame, modal, nominal_modal (so a loaded model has no
// modal report; host Engine::info() documents what it then lacks).
//
// Adding a field (another LoopParams or DeviceModel member): one line in
// visit_fields (image/fields.hpp) at the marked spot (a contact law's
// coefficients come from its kernel: coefficients(), contact.hpp); the
// size, field count and layout check follow from it (a host and a node then
// need the same sources). A member
// added at the end of LoopParams or of the VI NES DeviceModel without its
// line stops the build (static_assert tripwires naming the last member
// carried: move them to the new one). Bump kVersion when the meaning of
// existing fields changes.
//
// Firmware rules: header-only, no heap, no exceptions, no RTTI, no OS call;
// the Loader holds a pointer to the model (keep the model static) and a few
// dozen bytes of state, never a copy of the image.
//
// The parts: image/codec.hpp (entries and their wire form), image/fields.hpp
// (the field list), image/header.hpp (header, size, write_image),
// image/loader.hpp (Loader).
#pragma once

#include "vines/image/codec.hpp"
#include "vines/image/fields.hpp"
#include "vines/image/header.hpp"
#include "vines/image/loader.hpp"
