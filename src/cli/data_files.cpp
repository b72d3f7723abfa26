#include "data_files.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "common.hpp"
#include "output.hpp"

#if LPI_CLI_HAVE_HDF5
#include <hdf5.h>
#include <hdf5_hl.h>
#endif

namespace lpi_cli {

namespace {

std::size_t element_count(const std::vector<std::size_t> &shape, bool *too_many) {
    std::size_t count = 1;
    *too_many = false;
    for (std::size_t n : shape) {
        if (n != 0 && count > kMaxArrayValues / n) *too_many = true;
        count = *too_many ? 0 : count * n;
    }
    return count;
}

// Little-endian bytes, whatever the host's order.
void put_le(std::uint64_t v, unsigned char *out) {
    for (int i = 0; i < 8; ++i) out[i] = static_cast<unsigned char>(v >> (8 * i));
}
std::uint64_t get_le(const unsigned char *in, int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(in[i]) << (8 * i);
    return v;
}

// What a .npy header's dictionary says.
struct NpyHeader {
    std::string descr;
    bool fortran_order = false;
    std::vector<std::size_t> shape;
};

// Text from a file, for a message: printable ASCII, at most 40 characters.
std::string shown(const std::string &text) {
    std::string out;
    for (char c : text.substr(0, 40)) out += c >= ' ' && c <= '~' ? c : '?';
    return text.size() > 40 ? out + "..." : out;
}

// The dictionary of a .npy header, read as NumPy reads it (a Python literal
// with exactly the keys 'descr', 'fortran_order' and 'shape'), so that a file
// NumPy refuses is refused here too, not read in some other way: a shape
// "(3 3)" or "(9)" (no tuple), a key twice, another key, anything after the
// closing brace but the padding.
class HeaderParser {
public:
    explicit HeaderParser(const std::string &text)
        : p_(text.c_str()), end_(text.c_str() + text.size()) {}

    // "" or what is wrong with the dictionary.
    std::string parse(NpyHeader &h) {
        bool have_descr = false, have_order = false, have_shape = false;
        skip_space();
        if (!take('{')) return "the header is not a dictionary";
        for (;;) {
            skip_space();
            if (p_ == end_) return "the header's dictionary has no closing '}'";
            if (take('}')) break;
            std::string key;
            if (!string_literal(key)) return "a key of the header's dictionary is not a string";
            skip_space();
            if (!take(':')) return "no ':' after '" + shown(key) + "' in the header";
            skip_space();
            bool *seen = key == "descr" ? &have_descr : key == "fortran_order" ? &have_order
                       : key == "shape" ? &have_shape : nullptr;
            if (!seen)
                return "the header has a key '" + shown(key) +
                       "' (a .npy header has 'descr', 'fortran_order' and 'shape' only)";
            if (*seen) return "the header has the key '" + key + "' twice";
            *seen = true;
            if (key == "descr" && !string_literal(h.descr)) return "the header's descr is not a string";
            if (key == "fortran_order" && !boolean(h.fortran_order))
                return "the header's fortran_order is not True or False";
            if (key == "shape" && !tuple(h.shape))
                return "the header's shape is not a tuple of sizes below 2^28";
            skip_space();
            if (take(',')) continue;
            skip_space();
            if (take('}')) break;
            if (p_ == end_) return "the header's dictionary has no closing '}'";
            return "no ',' or '}' after the header's '" + key + "'";
        }
        skip_space();
        if (p_ != end_) return "the header has more after its dictionary";
        if (!have_descr) return "the header has no descr";
        if (!have_order) return "the header has no fortran_order";
        if (!have_shape) return "the header has no shape";
        return "";
    }

private:
    void skip_space() {
        while (p_ != end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\n' || *p_ == '\r')) ++p_;
    }
    bool take(char c) {
        if (p_ == end_ || *p_ != c) return false;
        ++p_;
        return true;
    }
    bool word(const char *w) {
        const std::size_t n = std::strlen(w);
        if (static_cast<std::size_t>(end_ - p_) < n || std::memcmp(p_, w, n) != 0) return false;
        p_ += n;
        return true;
    }
    // 'text' or "text" without escapes (NumPy writes none in these values).
    bool string_literal(std::string &out) {
        if (p_ == end_ || (*p_ != '\'' && *p_ != '"')) return false;
        const char quote = *p_++;
        const char *start = p_;
        while (p_ != end_ && *p_ != quote && *p_ != '\\' && *p_ != '\n') ++p_;
        if (p_ == end_ || *p_ != quote) return false;
        out.assign(start, p_);
        ++p_;
        return true;
    }
    bool boolean(bool &out) {
        if (word("True")) out = true;
        else if (word("False")) out = false;
        else return false;
        return true;
    }
    // A decimal size as Python writes it (no sign, no leading zero).
    bool size(std::size_t &out) {
        if (p_ == end_ || *p_ < '0' || *p_ > '9') return false;
        if (*p_ == '0' && p_ + 1 != end_ && p_[1] >= '0' && p_[1] <= '9') return false;
        std::size_t n = 0;
        for (; p_ != end_ && *p_ >= '0' && *p_ <= '9'; ++p_) {
            n = 10 * n + static_cast<std::size_t>(*p_ - '0');
            if (n > kMaxArrayValues) return false;
        }
        out = n;
        return true;
    }
    // () or (a,) or (a, b, ...) with an optional trailing comma: (a) is a
    // number, not a tuple.
    bool tuple(std::vector<std::size_t> &out) {
        out.clear();
        if (!take('(')) return false;
        skip_space();
        if (take(')')) return true;
        for (;;) {
            std::size_t n = 0;
            if (!size(n)) return false;
            out.push_back(n);
            skip_space();
            const bool comma = take(',');
            skip_space();
            if (take(')')) return comma || out.size() > 1;
            if (!comma) return false;
        }
    }

    const char *p_, *end_;
};

}  // namespace

constexpr std::size_t kMaxDimensions = 64;

std::string npy_header(const Array &a) {
    std::string dict = std::string("{'descr': '") + (a.integer ? "<i8" : "<f8") +
                       "', 'fortran_order': False, 'shape': (";
    for (std::size_t n : a.shape) dict += std::to_string(n) + (a.shape.size() == 1 ? ",)" : ", ");
    if (a.shape.size() != 1) {
        if (!a.shape.empty()) dict.resize(dict.size() - 2);
        dict += ")";
    }
    dict += ", }";
    // magic (6) + version (2) + length (2) + dictionary + padding + '\n':
    // format 1.0 states the length in 2 bytes, which hold any header of at
    // most kMaxDimensions sizes (read_npy takes no more).
    std::size_t total = 10 + dict.size() + 1;
    total = (total + 63) / 64 * 64;
    dict.append(total - 10 - 1 - dict.size(), ' ');
    dict += '\n';
    const std::size_t length = dict.size();
    std::string header("\x93NUMPY\x01\x00", 8);
    header += static_cast<char>(length & 0xff);
    header += static_cast<char>(length >> 8);
    return header + dict;
}

std::string npy_values(const std::vector<double> &values, bool integer, std::size_t from, std::size_t to) {
    std::string bytes(8 * (to - from), '\0');
    for (std::size_t i = from; i < to; ++i) {
        std::uint64_t bits;
        if (integer) {
            bits = static_cast<std::uint64_t>(static_cast<std::int64_t>(values[i]));
        } else {
            std::memcpy(&bits, &values[i], 8);
        }
        put_le(bits, reinterpret_cast<unsigned char *>(&bytes[8 * (i - from)]));
    }
    return bytes;
}

std::string npy_file(const Array &a) { return npy_header(a) + npy_values(a.values, a.integer, 0, a.values.size()); }

namespace {

// read_npy of an opened file.
std::string parse_npy(RegularFileReader &f, Array &a, bool tail_allowed) {
    unsigned char start[12];
    if (f.read(start, 10) != 10 || std::memcmp(start, "\x93NUMPY", 6) != 0)
        return "not a NumPy .npy file (no \\x93NUMPY magic)";
    const int major = start[6];
    std::size_t length = 0;
    if (major == 1) {
        length = get_le(start + 8, 2);
    } else if (major == 2 || major == 3) {
        if (f.read(start + 10, 2) != 2) return "truncated header";
        length = get_le(start + 8, 4);
    } else {
        return "NumPy format version " + std::to_string(major) + " is not known here (1, 2 or 3)";
    }
    if (length > 1 << 20) return "header length " + std::to_string(length) + " is absurd";
    std::string header(length, '\0');
    if (f.read(reinterpret_cast<unsigned char *>(&header[0]), length) != length) return "truncated header";
    const std::size_t data_bytes = f.size() - (major == 1 ? 10 : 12) - length;
    NpyHeader fields;
    const std::string unreadable = HeaderParser(header).parse(fields);
    if (!unreadable.empty()) return unreadable;
    const std::string &descr = fields.descr;
    int item = 0;
    bool integer = false;
    if (descr == "<f8") item = 8;
    else if (descr == "<f4") item = 4;
    else if (descr == "<i8") item = 8, integer = true;
    else if (descr == "<i4") item = 4, integer = true;
    else return "dtype '" + shown(descr) + "' is not read here (little-endian float64, float32, int64 or int32)";
    Array out;
    out.integer = integer;
    out.shape = fields.shape;
    bool too_many = false;
    const std::size_t count = element_count(out.shape, &too_many);
    // NumPy's own limit (NPY_MAXDIMS, 64 since NumPy 2): also what keeps
    // the header npy_header writes back within format 1.0's 65535 bytes.
    if (out.shape.size() > kMaxDimensions)
        return std::to_string(out.shape.size()) + " dimensions, more than NumPy's " +
               std::to_string(kMaxDimensions);
    if (too_many) return "more than 2^28 values";
    // Compared with the file's size before anything is allocated for it: a
    // header alone could otherwise make lpi allocate gigabytes.
    if (count * item > data_bytes) return "truncated: the data is shorter than its shape says";
    std::vector<unsigned char> bytes(count * item);
    if (f.read(bytes.data(), bytes.size()) != bytes.size())
        return "truncated: the data is shorter than its shape says";
    unsigned char extra;
    if (!tail_allowed && f.read(&extra, 1) != 0) return "bytes after the data its shape says";
    out.values.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint64_t bits = get_le(&bytes[i * item], item);
        if (integer) {
            out.values[i] = item == 8 ? static_cast<double>(static_cast<std::int64_t>(bits))
                                      : static_cast<double>(static_cast<std::int32_t>(bits));
        } else if (item == 8) {
            std::memcpy(&out.values[i], &bits, 8);
        } else {
            const std::uint32_t b32 = static_cast<std::uint32_t>(bits);
            float v;
            std::memcpy(&v, &b32, 4);
            out.values[i] = v;  // exact
        }
    }
    if (fields.fortran_order && out.shape.size() > 1) {
        // Fortran order: the first index runs fastest. Reorder to C order.
        std::vector<double> c_order(count);
        std::vector<std::size_t> index(out.shape.size(), 0);
        for (std::size_t k = 0; k < count; ++k) {
            std::size_t c = 0;
            for (std::size_t d = 0; d < out.shape.size(); ++d) c = c * out.shape[d] + index[d];
            c_order[c] = out.values[k];
            for (std::size_t d = 0; d < out.shape.size() && ++index[d] == out.shape[d]; ++d) index[d] = 0;
        }
        out.values.swap(c_order);
    }
    a = std::move(out);
    return "";
}

}  // namespace

std::string read_npy(const std::string &path, Array &a, bool tail_allowed) {
    std::string why;
    const std::string unreadable = failure_of([&] {
        RegularFileReader f(path);
        why = parse_npy(f, a, tail_allowed);
    });
    return unreadable.empty() ? why : unreadable;
}

std::string read_json_attributes(const std::string &path, std::vector<Attribute> &attributes,
                                 std::vector<std::string> &found) {
    found.clear();
    std::string text;
    const std::string unreadable = read_input(path, text);
    if (!unreadable.empty()) return unreadable;
    std::size_t at = 0;
    auto skip_space = [&] {
        while (at < text.size() && (text[at] == ' ' || text[at] == '\n' || text[at] == '\t' || text[at] == '\r')) ++at;
    };
    auto string_at = [&](std::string &out) {
        out.clear();
        if (at >= text.size() || text[at] != '"') return false;
        for (++at; at < text.size() && text[at] != '"'; ++at) {
            if (text[at] == '\\' && ++at == text.size()) return false;
            out += text[at];
        }
        return at++ < text.size();
    };
    const std::string wrong = path + ": not the attributes lpi writes";
    skip_space();
    if (at >= text.size() || text[at++] != '{') return wrong;
    for (skip_space(); at < text.size() && text[at] != '}';) {
        std::string key, value;
        if (!string_at(key)) return wrong;
        skip_space();
        if (at >= text.size() || text[at++] != ':') return wrong;
        skip_space();
        Attribute read;
        read.is_text = at < text.size() && text[at] == '"';
        if (read.is_text) {
            if (!string_at(read.text)) return wrong;
        } else {
            const std::size_t end = text.find_first_of(",} \n", at);
            if (end == std::string::npos || !decimal_problem(text.substr(at, end - at), read.number).empty())
                return wrong;
            at = end;
        }
        for (Attribute &attr : attributes)
            if (attr.name == key && attr.is_text == read.is_text) {
                if (read.is_text) attr.text = read.text;
                else attr.number = read.number;
                found.push_back(key);
            }
        skip_space();
        if (at < text.size() && text[at] == ',') ++at, skip_space();
    }
    return at < text.size() ? "" : wrong;
}

bool is_hdf5_file(const std::string &path) {
    // The signature is at offset 0 or, after a user block, 512, 1024, ...
    // A file that is not regular (a FIFO) is none: its reader says so.
    std::vector<unsigned char> start;
    const std::string unreadable = failure_of([&] {
        RegularFileReader f(path);
        start.resize(std::min<std::size_t>(f.size(), (std::size_t(1) << 20) + 8));
        start.resize(f.read(start.data(), start.size()));
    });
    if (!unreadable.empty()) return false;
    for (std::size_t offset = 0; offset + 8 <= start.size(); offset = offset ? 2 * offset : 512)
        if (std::memcmp(&start[offset], "\x89HDF\r\n\x1a\n", 8) == 0) return true;
    return false;
}

#if LPI_CLI_HAVE_HDF5

namespace {

// An HDF5 identifier. close() closes it and says whether that worked; the
// destructor closes one still open, on a path that has failed already.
class Id {
public:
    Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
    Id(const Id &) = delete;
    Id &operator=(const Id &) = delete;
    ~Id() {
        if (id_ >= 0) close_(id_);
    }
    hid_t get() const { return id_; }
    bool ok() const { return id_ >= 0; }
    bool close() {
        const hid_t id = id_;
        id_ = -1;
        return id >= 0 && close_(id) >= 0;
    }

private:
    hid_t id_;
    herr_t (*close_)(hid_t);
};

// HDF5 prints its error stack by default; lpi reports failures itself.
void quiet_hdf5() {
    static const bool quiet = [] { return H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr) >= 0; }();
    (void)quiet;
}

std::string write_attribute(hid_t file, const Attribute &attr) {
    Id space(H5Screate(H5S_SCALAR), H5Sclose);
    bool written = false;
    if (attr.is_text) {
        Id type(H5Tcopy(H5T_C_S1), H5Tclose);
        Id a(type.ok() && H5Tset_size(type.get(), H5T_VARIABLE) >= 0 && H5Tset_cset(type.get(), H5T_CSET_UTF8) >= 0
                 ? H5Acreate2(file, attr.name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT)
                 : -1,
             H5Aclose);
        const char *text = attr.text.c_str();
        written = a.ok() && H5Awrite(a.get(), type.get(), &text) >= 0 && a.close() && type.close();
    } else if (attr.integer) {
        const std::int64_t whole = static_cast<std::int64_t>(attr.number);
        Id a(H5Acreate2(file, attr.name.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
        written = a.ok() && H5Awrite(a.get(), H5T_NATIVE_INT64, &whole) >= 0 && a.close();
    } else {
        Id a(H5Acreate2(file, attr.name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose);
        written = a.ok() && H5Awrite(a.get(), H5T_NATIVE_DOUBLE, &attr.number) >= 0 && a.close();
    }
    return written && space.close() ? "" : "attribute " + attr.name;
}

}  // namespace

bool have_hdf5() { return true; }

// The file is built in memory (the core driver, no backing store) and its
// image written as every other output is: HDF5 writing a file on disk by
// name leaves, when a write fails (a full disk), a file it cannot close,
// which its shutdown at exit then crashes on.
std::string write_hdf5(const std::string &path, const std::vector<Dataset> &datasets,
                       const std::vector<Attribute> &attributes, std::vector<std::uint64_t> *offsets) {
    quiet_hdf5();
    // Probed first, as the other writers do, so that no work is done for a
    // target that cannot be replaced.
    std::string why = output_problem(path);
    if (!why.empty()) return why;
    std::vector<unsigned char> image;
    {
        Id access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
        if (!access.ok() || H5Pset_fapl_core(access.get(), std::size_t(1) << 20, false) < 0)
            return "HDF5 cannot make a file in memory";
        Id file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get()), H5Fclose);
        if (!file.ok()) return "HDF5 cannot create " + path + " in memory";
        // No modification times in the objects: the same run gives the same bytes.
        Id creation(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
        if (!creation.ok() || H5Pset_obj_track_times(creation.get(), false) < 0)
            return "HDF5 cannot set up a dataset";
        std::vector<std::unique_ptr<Id>> ids;
        offsets->clear();
        for (const Dataset &d : datasets) {
            std::vector<hsize_t> dims(d.array.shape.begin(), d.array.shape.end());
            Id space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
            const hid_t file_type = d.array.integer ? H5T_STD_I64LE : H5T_IEEE_F64LE;
            ids.push_back(std::make_unique<Id>(
                H5Dcreate2(file.get(), d.name.c_str(), file_type, space.get(), H5P_DEFAULT, creation.get(), H5P_DEFAULT),
                H5Dclose));
            const hid_t set = ids.back()->get();
            if (set < 0 || !space.close()) return "HDF5 cannot create dataset " + d.name;
            herr_t status = 0;
            if (d.array.values.empty()) {
                // nothing to write: an empty dataset has no raw data
            } else if (d.array.integer) {
                std::vector<std::int64_t> whole(d.array.values.begin(), d.array.values.end());
                status = H5Dwrite(set, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, whole.data());
            } else {
                status = H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.array.values.data());
            }
            if (status < 0) return "HDF5 cannot write dataset " + d.name;
            const haddr_t at = H5Dget_offset(set);
            offsets->push_back(at == HADDR_UNDEF ? UINT64_MAX : static_cast<std::uint64_t>(at));
            if (d.is_scale && H5DSset_scale(set, d.name.c_str()) < 0) return "HDF5 cannot make " + d.name + " a scale";
        }
        for (std::size_t i = 0; i < datasets.size(); ++i)
            for (std::size_t axis = 0; axis < datasets[i].dims.size(); ++axis) {
                const std::string &scale = datasets[i].dims[axis];
                if (scale.empty()) continue;
                for (std::size_t j = 0; j < datasets.size(); ++j)
                    if (datasets[j].name == scale &&
                        H5DSattach_scale(ids[i]->get(), ids[j]->get(), static_cast<unsigned>(axis)) < 0)
                        return "HDF5 cannot attach " + scale + " to " + datasets[i].name;
            }
        for (const Attribute &attr : attributes) {
            why = write_attribute(file.get(), attr);
            if (!why.empty()) return "HDF5 cannot write " + why;
        }
        for (auto &id : ids)
            if (!id->close()) return "HDF5 cannot close a dataset of " + path;
        if (!creation.close()) return "HDF5 cannot close a property list";
        // The image of the whole file, its superblock flushed (which
        // H5Fget_file_image alone leaves as it was at creation).
        if (H5Fflush(file.get(), H5F_SCOPE_GLOBAL) < 0) return "HDF5 cannot flush " + path + " in memory";
        const ssize_t size = H5Fget_file_image(file.get(), nullptr, 0);
        if (size <= 0) return "HDF5 cannot make the image of " + path;
        image.resize(static_cast<std::size_t>(size));
        if (H5Fget_file_image(file.get(), image.data(), image.size()) != size || !file.close() || !access.close())
            return "HDF5 cannot make the image of " + path;
    }
    return failure_of([&] { lpi::write_file_atomically(path, image.data(), image.size()); });
}

std::string read_hdf5_attributes(const std::string &path, std::vector<Attribute> &attributes,
                                 std::vector<std::string> &found) {
    quiet_hdf5();
    found.clear();
    if (!is_hdf5_file(path)) return "not an HDF5 file";
    Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!file.ok()) return "HDF5 cannot open it (damaged?)";
    for (Attribute &attr : attributes) {
        if (H5Aexists(file.get(), attr.name.c_str()) <= 0) continue;
        Id a(H5Aopen(file.get(), attr.name.c_str(), H5P_DEFAULT), H5Aclose);
        Id type(a.ok() ? H5Aget_type(a.get()) : -1, H5Tclose);
        if (!type.ok()) return "HDF5 cannot read its attribute " + attr.name;
        const bool text = H5Tget_class(type.get()) == H5T_STRING;
        if (text != attr.is_text) continue;  // not the attribute lpi writes: as good as none
        if (text) {
            if (H5Tis_variable_str(type.get()) <= 0) continue;
            Id memory(H5Tcopy(H5T_C_S1), H5Tclose);
            char *value = nullptr;
            if (!memory.ok() || H5Tset_size(memory.get(), H5T_VARIABLE) < 0 ||
                H5Tset_cset(memory.get(), H5T_CSET_UTF8) < 0 || H5Aread(a.get(), memory.get(), &value) < 0)
                return "HDF5 cannot read its attribute " + attr.name;
            attr.text = value ? value : "";
            H5free_memory(value);
        } else if (H5Aread(a.get(), H5T_NATIVE_DOUBLE, &attr.number) < 0) {
            return "HDF5 cannot read its attribute " + attr.name;
        }
        found.push_back(attr.name);
    }
    return file.close() ? "" : "HDF5 cannot close it";
}

std::string read_hdf5(const std::string &path, const std::string &name, Array &a, bool *found) {
    quiet_hdf5();
    *found = false;
    if (!is_hdf5_file(path)) return "not an HDF5 file";
    Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!file.ok()) return "HDF5 cannot open it (damaged?)";
    if (H5Lexists(file.get(), name.c_str(), H5P_DEFAULT) <= 0) return "no dataset " + name;
    *found = true;
    Id set(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    if (!set.ok()) return name + " is not a dataset";
    Id type(H5Dget_type(set.get()), H5Tclose);
    const H5T_class_t kind = H5Tget_class(type.get());
    if (kind != H5T_FLOAT && kind != H5T_INTEGER) return name + " holds neither floats nor integers";
    Id space(H5Dget_space(set.get()), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0 || rank > 8) return name + " has an unreadable shape";
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    Array out;
    out.integer = kind == H5T_INTEGER;
    out.shape.assign(dims.begin(), dims.end());
    bool too_many = false;
    const std::size_t count = element_count(out.shape, &too_many);
    if (too_many) return name + " has more than 2^28 values";
    // What the shape claims must be in the file before anything is allocated
    // for it: at most the file's size, or deflate's greatest ratio (1032:1)
    // times it for a compressed dataset.
    const std::size_t item = H5Tget_size(type.get());
    hsize_t file_size = 0;
    Id creation(H5Dget_create_plist(set.get()), H5Pclose);
    const int filters = creation.ok() ? H5Pget_nfilters(creation.get()) : -1;
    if (item == 0 || filters < 0 || H5Fget_filesize(file.get(), &file_size) < 0)
        return name + " has an unreadable layout";
    const double claimed = static_cast<double>(count) * static_cast<double>(item);
    if (claimed > static_cast<double>(file_size) * (filters > 0 ? 1032.0 : 1.0)) {
        *found = false;  // a damaged file, not a dataset of another shape
        return name + " claims more values than the file holds (truncated?)";
    }
    out.values.resize(count);
    if (count > 0 && H5Dread(set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.values.data()) < 0)
        return "HDF5 cannot read " + name + " (damaged?)";
    if (!creation.close() || !type.close() || !space.close() || !set.close() || !file.close())
        return "HDF5 cannot close it";
    a = std::move(out);
    return "";
}

#else

bool have_hdf5() { return false; }

std::string write_hdf5(const std::string &, const std::vector<Dataset> &, const std::vector<Attribute> &,
                       std::vector<std::uint64_t> *) {
    return "this lpi is built without HDF5";
}

std::string read_hdf5_attributes(const std::string &, std::vector<Attribute> &, std::vector<std::string> &found) {
    found.clear();
    return "this lpi is built without HDF5";
}

std::string read_hdf5(const std::string &, const std::string &, Array &, bool *found) {
    *found = false;
    return "this lpi is built without HDF5 (give a .npy file)";
}

#endif

}  // namespace lpi_cli
