// White-box tests of FileGrowth (src/core/files.hpp), the in-place growth of
// the files lpi run extends with each checkpoint: it grows only the file its
// writer left, and every way it can fail leaves that file's bytes as they
// were (cut back, the overwritten header restored).
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

// Before cmocka.h (through lpi_test.h), whose fail() macro would rewrite lpi::fail.
#include "core/error.hpp"
#include "core/files.hpp"
#include "lpi_test.h"

namespace {

std::string contents(const std::string &path) { return lpi::RegularFileReader(path).read_rest(); }

lpi::FileIdentity write_whole(const std::string &path, const std::string &text) {
    return lpi::write_file_atomically(path, reinterpret_cast<const unsigned char *>(text.data()), text.size());
}

void append(lpi::FileGrowth &g, const std::string &text) {
    g.append(reinterpret_cast<const unsigned char *>(text.data()), text.size());
}

void overwrite(lpi::FileGrowth &g, unsigned long long offset, const std::string &text) {
    g.overwrite(offset, reinterpret_cast<const unsigned char *>(text.data()), text.size());
}

// The message of the lpi::Error `f` throws, "" when it throws none.
template <class F>
std::string error_of(F &&f) {
    try {
        f();
    } catch (const lpi::Error &e) {
        assert_int_equal(e.status(), LPI_ERR_IO);
        return e.what();
    }
    return "";
}

struct Folder {
    char name[32] = "file_growth_XXXXXX";
    Folder() { assert_non_null(mkdtemp(name)); }
    ~Folder() {
        for (const char *file : {"/data", "/other"}) unlink((std::string(name) + file).c_str());
        rmdir(name);
    }
    std::string file(const char *leaf) const { return std::string(name) + "/" + leaf; }
};

// Grown: the appended bytes after the old, the header overwritten, and an
// identity that lets the next growth go on.
void test_grows_the_file_it_wrote(void **) {
    Folder folder;
    const std::string path = folder.file("data");
    lpi::FileIdentity id = write_whole(path, "0003abc");
    for (int round = 0; round < 3; ++round) {
        lpi::FileGrowth g(path, id);
        assert_true(g.possible());
        assert_int_equal(g.old_size(), 7 + 3 * round);
        append(g, "def");
        char header[5];
        std::snprintf(header, sizeof header, "%04d", 6 + 3 * round);
        overwrite(g, 0, header);
        id = g.commit();
    }
    assert_string_equal(contents(path).c_str(), "0012abcdefdefdef");
    struct stat st;
    assert_int_equal(stat(path.c_str(), &st), 0);
    assert_true(id.known);
    assert_int_equal(id.inode, st.st_ino);
    assert_int_equal(id.size, 16);
}

// Not the file it wrote, or not as it left it: nothing to grow, nothing touched.
void test_refuses_a_file_changed_since(void **) {
    Folder folder;
    const std::string path = folder.file("data");
    assert_false(lpi::FileGrowth(path, lpi::FileIdentity()).possible());  // never written
    const lpi::FileIdentity id = write_whole(path, "abc");
    // Grown by another writer (the same size would need the same mtime too).
    {
        const int fd = open(path.c_str(), O_WRONLY | O_APPEND);
        assert_true(fd >= 0);
        assert_int_equal(write(fd, "x", 1), 1);
        close(fd);
    }
    assert_false(lpi::FileGrowth(path, id).possible());
    assert_string_equal(contents(path).c_str(), "abcx");
    // Replaced (another inode), with the very bytes of the old.
    const lpi::FileIdentity replaced_id = write_whole(folder.file("other"), "abc");
    assert_int_equal(rename(folder.file("other").c_str(), path.c_str()), 0);
    assert_false(lpi::FileGrowth(path, id).possible());
    assert_true(lpi::FileGrowth(path, replaced_id).possible());
    // Gone.
    unlink(path.c_str());
    assert_false(lpi::FileGrowth(path, replaced_id).possible());
}

// Not committed (a failure elsewhere unwinds past it): the old bytes back.
void test_uncommitted_growth_is_undone(void **) {
    Folder folder;
    const std::string path = folder.file("data");
    const lpi::FileIdentity id = write_whole(path, "HEADERbody");
    {
        lpi::FileGrowth g(path, id);
        append(g, "more values");
        g.sync();
        overwrite(g, 0, "header");
        overwrite(g, 2, "AD");
        assert_string_equal(contents(path).c_str(), "heADerbodymore values");
    }
    assert_string_equal(contents(path).c_str(), "HEADERbody");
    // What is left is the file it wrote: a growth goes on from it.
    struct stat st;
    assert_int_equal(stat(path.c_str(), &st), 0);
    assert_int_equal(st.st_size, 10);
}

// A failure inside the growth: LPI_ERR_IO naming the file and the reason,
// and the file as it was, the header written before the failure restored.
void test_failures_leave_the_old_file(void **) {
    Folder folder;
    const std::string path = folder.file("data");
    const lpi::FileIdentity id = write_whole(path, "HEADERbody");
    // A write past RLIMIT_FSIZE (SIGXFSZ ignored, as a full disk would fail
    // it): refused before any byte goes past the limit.
    struct rlimit old_limit;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
    struct sigaction ignore = {}, old_action;
    ignore.sa_handler = SIG_IGN;
    assert_int_equal(sigaction(SIGXFSZ, &ignore, &old_action), 0);
    struct rlimit limit = old_limit;
    limit.rlim_cur = 64;
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &limit), 0);
    std::string why = error_of([&] {
        lpi::FileGrowth g(path, id);
        overwrite(g, 0, "header");
        append(g, "12345678");
        append(g, std::string(100, 'v'));
    });
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &old_limit), 0);
    assert_int_equal(sigaction(SIGXFSZ, &old_action, nullptr), 0);
    assert_non_null(std::strstr(why.c_str(), path.c_str()));
    assert_non_null(std::strstr(why.c_str(), "File too large"));
    assert_string_equal(contents(path).c_str(), "HEADERbody");
    // An overwrite past the old end is refused, the append before it undone.
    // (A writer whose growth failed replaces the file whole next.)
    const lpi::FileIdentity rewritten = write_whole(path, "HEADERbody");
    why = error_of([&] {
        lpi::FileGrowth g(path, rewritten);
        assert_true(g.possible());
        append(g, "tail");
        overwrite(g, 8, "xyz");
    });
    assert_non_null(std::strstr(why.c_str(), "past its old end"));
    assert_string_equal(contents(path).c_str(), "HEADERbody");
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grows_the_file_it_wrote),
        cmocka_unit_test(test_refuses_a_file_changed_since),
        cmocka_unit_test(test_uncommitted_growth_is_undone),
        cmocka_unit_test(test_failures_leave_the_old_file),
    };
    return lpi_run_tests(tests);
}
