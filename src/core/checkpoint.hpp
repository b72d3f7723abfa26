// Checkpoints: a System written to bytes (or a file) and read back so that
// stepping continues the same trajectory to the bit.
//
// Format, version 2. Every number is in the writer's byte order, announced by
// the marker; IEEE 754 doubles are stored as their 8 bytes.
//   offset  0  magic        8 bytes  89 'L' 'P' 'I' 0D 0A 1A 0A (PNG-style:
//                                    catches text-mode and 7-bit transfers)
//           8  byte order   u32      0x01020304 as written
//          12  version      u32      1
//          16  total size   u64      bytes in the whole checkpoint
//          24  payload:
//              kind         string   Model::kind(), one of checkpoint_kinds()
//              parameters   u32 n, n x f64   (Model::checkpoint_parameters)
//              split        string
//              method       string   registry name, or "custom"
//              gammas       u32 n, n x f64   (the composition's weights)
//              tolerance    f64      implicit settings
//              iterations   i32
//              time         f64
//              time carry   f64      (version 2 on) time + carry is the time
//                                    exactly (System::Time); version 1: 0
//              state        u64 n, n x f64   (the working layout, including
//                                              the compensated carry)
//   size-4     CRC-32       u32      of every byte before it (IEEE 802.3)
// A string is u32 length + bytes (printable ASCII, at most 256). Threads are a runtime setting
// (results are identical for every count) and are not stored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "system.hpp"

namespace lpi {

constexpr std::uint32_t kCheckpointVersion = 2;

// How a checkpoint brings a model kind back. Each model kind that can be
// saved (Model::checkpoint_parameters) has one, listed in checkpoint_kinds().
// parameter_count kCheckedByKind: the count varies, state_size checks it.
constexpr std::size_t kCheckedByKind = static_cast<std::size_t>(-1);
struct CheckpointKind {
    const char *kind;  // Model::kind()
    std::size_t parameter_count;  // or kCheckedByKind
    // The working-state length of the model these parameters (of the right
    // count) describe, without building it: a crafted file must not make the
    // library allocate a model far larger than the file. Throws lpi::Error
    // for parameters no setter would accept.
    std::uint64_t (*state_size)(const std::vector<double> &parameters);
    // Builds the model (throws lpi::Error for invalid parameters).
    std::unique_ptr<Model> (*build)(const std::vector<double> &parameters);
    // Throws lpi::Error unless the (finite) working state is one the model's
    // own operations produce; nullptr when every finite state is.
    void (*check_state)(const Model &model, const double *state);
};

// Every kind a checkpoint can name (defined in src/registry.cpp).
const std::vector<CheckpointKind> &checkpoint_kinds();

// CRC-32 (reflected polynomial 0xEDB88320, init and final xor 0xFFFFFFFF: the
// checksum of zlib, PNG and IEEE 802.3; check value 0xCBF43926 for "123456789").
std::uint32_t crc32(const unsigned char *data, std::size_t size);

// The checkpoint of a system; LPI_ERR_UNSUPPORTED for models that cannot be
// saved (generic systems: their pieces are user callbacks) or whose kind has
// no CheckpointKind (it could not be loaded).
std::vector<unsigned char> encode_checkpoint(const System &system);

// A decoded, validated checkpoint: the model is built (split selected), the
// rest is applied to a System around it by restore_checkpoint.
struct Checkpoint {
    std::unique_ptr<Model> model;
    std::string method;
    std::vector<double> gammas;
    ImplicitSettings implicit;
    double time = 0.0, time_carry = 0.0;
    std::vector<double> state;
};

// Throws LPI_ERR_FORMAT for anything that is not an intact checkpoint this
// library can read (truncated, corrupted, wrong magic, other byte order, newer
// version, inconsistent contents, or contents no setter would accept: every
// parameter and the working state are validated as strictly as user input),
// with a message saying which; LPI_ERR_UNSUPPORTED for a kind this build
// cannot make (sine-Euler without FFTW). Memory in proportion to `size`,
// whatever the contents claim.
Checkpoint decode_checkpoint(const unsigned char *data, std::size_t size);
// Sets method, implicit settings, state and time; LPI_ERR_FORMAT when this
// build's method of that name has other coefficients than the checkpoint's,
// or the name is an alias (a checkpoint stores the name itself).
void restore_checkpoint(System &system, const Checkpoint &checkpoint);

// The bytes of the checkpoint file at path, read bounded: the header is
// checked against the file's size (LPI_ERR_FORMAT) before anything of that
// size is allocated. LPI_ERR_IO when it cannot be read or is no regular file
// (files.hpp: the saves are write_file_atomically's).
std::vector<unsigned char> read_checkpoint_file(const std::string &path);

}  // namespace lpi
