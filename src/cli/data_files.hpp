// The data lpi run keeps, in formats other programs read: NumPy's .npy
// (written and read here, no library) and, when lpi is built with HDF5, one
// HDF5 file per run (h5py, xarray through h5netcdf, HDFView).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace lpi_cli {

// The most values lpi reads from one array (2 GiB of doubles): a bound on
// what a corrupt or hostile header can make it allocate, and so on what a
// run may write and still resume from.
constexpr std::size_t kMaxArrayValues = std::size_t(1) << 28;

// An n-dimensional array in C order. `integer` arrays (steps) are stored as
// 64-bit integers; their values are whole numbers below 2^53.
struct Array {
    std::vector<std::size_t> shape;
    std::vector<double> values;
    bool integer = false;
};

// The NumPy format 1.0 header of an array: magic, version, the dictionary
// ('<f8' or '<i8', C order), padded with spaces to a multiple of 64 bytes.
std::string npy_header(const Array &a);

// The bytes of `a` as a .npy file: its header, then the values.
std::string npy_file(const Array &a);

// The bytes of values [from, to), as npy_file stores them (64-bit integers
// where `integer`, else doubles, little-endian).
std::string npy_values(const std::vector<double> &values, bool integer, std::size_t from, std::size_t to);

// Reads a .npy file (format 1.0, 2.0 or 3.0) of little-endian float64,
// float32, int64 or int32, in C or Fortran order, into C order. Returns "" or
// what is wrong with the file. Bytes after the values its shape says are
// refused, unless `tail_allowed` (data lpi grows in place: the tail of a
// growth that a kill cut short, before the header took the new length;
// NumPy reads past it too).
std::string read_npy(const std::string &path, Array &a, bool tail_allowed = false);

// One dataset of an HDF5 file. `dims` names, per axis, the dataset that is the
// dimension scale of that axis ("" for none); a dataset that is itself a
// dimension scale has is_scale set (and no dims).
struct Dataset {
    std::string name;
    Array array;
    std::vector<std::string> dims;
    bool is_scale = false;
};

// A scalar attribute of the file's root group: text, or a number (stored as
// a 64-bit integer when `integer`).
struct Attribute {
    std::string name;
    std::string text;
    double number = 0.0;
    bool is_text = true;
    bool integer = false;
};

// Whether this lpi reads and writes HDF5.
bool have_hdf5();

// Writes the datasets (contiguous, so that other programs, gnuplot among
// them, can read the raw data at a byte offset) and the attributes to one
// HDF5 file, made in memory and written atomically (output.hpp). `offsets`
// receives, per dataset, the byte offset of its raw data in the file.
// Returns "" or the reason it failed.
std::string write_hdf5(const std::string &path, const std::vector<Dataset> &datasets,
                       const std::vector<Attribute> &attributes, std::vector<std::uint64_t> *offsets);

// The root attributes of an HDF5 file named in `attributes` (their names
// given, is_text telling text from numbers): those found are read, and
// `found` lists their names. Returns "" or the reason the file cannot be read.
std::string read_hdf5_attributes(const std::string &path, std::vector<Attribute> &attributes,
                                 std::vector<std::string> &found);

// The same from attributes.json as lpi writes it (an object of strings and
// numbers).
std::string read_json_attributes(const std::string &path, std::vector<Attribute> &attributes,
                                 std::vector<std::string> &found);

// Whether the file exists and holds the HDF5 signature.
bool is_hdf5_file(const std::string &path);

// Reads the dataset `name` of an HDF5 file as doubles. `found` tells a
// missing dataset apart from an unreadable file (one whose dataset claims
// more values than the file holds is unreadable). Returns "" or the reason.
std::string read_hdf5(const std::string &path, const std::string &name, Array &a, bool *found);

}  // namespace lpi_cli
