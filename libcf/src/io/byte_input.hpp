#pragma once
// Private: a graph file's bytes, read in pieces from a file or taken from memory, so that a
// reader never needs the whole file in memory (docs/graph-format.md, "Reading").

#include <cstddef>
#include <streambuf>
#include <string>
#include <vector>

namespace cf::internal {

/// The bytes of one input: an open file (read with pread, never whole) or a caller's memory.
/// Either can be read from any offset any number of times (the header scan reads the start
/// again).
class ByteInput {
 public:
  /// A file opened by open_input_file; the ByteInput closes it.
  ByteInput(int fd, std::size_t size, const std::string& source);
  /// The caller's bytes, which must outlive the ByteInput.
  ByteInput(const char* data, std::size_t size, const std::string& source);
  ~ByteInput();
  ByteInput(const ByteInput&) = delete;
  ByteInput& operator=(const ByteInput&) = delete;

  /// Bytes when opened: a file that grows while it is read is read to its first size.
  std::size_t size() const { return size_; }
  const std::string& source() const { return source_; }
  /// Copies up to `n` bytes from `offset` into `dst`; fewer only at the end.
  /// @throws cf::Error "reading '<source>': read failed: <reason>".
  std::size_t read_at(std::size_t offset, char* dst, std::size_t n) const;

 private:
  int fd_ = -1;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  const std::string& source_;
};

/// A std::streambuf over a ByteInput from its start, in 64 KiB pieces: what nlohmann's CBOR
/// reader takes.
class ByteInputBuf final : public std::streambuf {
 public:
  explicit ByteInputBuf(const ByteInput& in) : in_(in), buf_(kPiece) {}

 protected:
  int_type underflow() override;

 private:
  static constexpr std::size_t kPiece = std::size_t{64} << 10;
  const ByteInput& in_;
  std::vector<char> buf_;
  std::size_t next_ = 0;  // offset of the next piece
};

}  // namespace cf::internal
