#include "vrdeform/web/tls_identity.h"

#include <fmt/format.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>

#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

template <auto Free>
struct Deleter {
  template <typename T>
  void operator()(T* p) const {
    Free(p);
  }
};
using Bio = std::unique_ptr<BIO, Deleter<BIO_free_all>>;
using Key = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Deleter<X509_free>>;
using Extension = std::unique_ptr<X509_EXTENSION, Deleter<X509_EXTENSION_free>>;

constexpr int kValidDays = 825;  // the longest a browser accepts for a leaf certificate

// OpenSSL's reason for the last failure, for a message.
std::string openSslError() {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return "unknown OpenSSL error";
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  return text;
}

[[noreturn]] void fail(std::string_view what) { throw Error(fmt::format("tls: {}: {}", what, openSslError())); }

std::string pemOf(auto write) {
  Bio bio(BIO_new(BIO_s_mem()));
  if (!bio || !write(bio.get())) fail("cannot write PEM");
  char* data = nullptr;
  const long size = BIO_get_mem_data(bio.get(), &data);
  return std::string(data, std::size_t(size));
}

std::string hex(const unsigned char* bytes, unsigned size) {
  std::string s;
  for (unsigned i = 0; i < size; ++i) s += fmt::format("{}{:02X}", i ? ":" : "", bytes[i]);
  return s;
}

std::string base64(const unsigned char* bytes, int size) {
  std::string out(std::size_t(4 * ((size + 2) / 3)) + 1, '\0');
  const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()), bytes, size);
  out.resize(std::size_t(n));
  return out;
}

// Fills in the fingerprint and the public key's hash.
void describe(TlsIdentity& id, X509* cert, EVP_PKEY* key) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned size = 0;
  if (!X509_digest(cert, EVP_sha256(), md, &size)) fail("cannot hash the certificate");
  id.fingerprint = hex(md, size);
  unsigned char* der = nullptr;
  const int length = i2d_PUBKEY(key, &der);
  if (length <= 0) fail("cannot encode the public key");
  EVP_Digest(der, std::size_t(length), md, &size, EVP_sha256(), nullptr);
  OPENSSL_free(der);
  id.spkiHash = base64(md, int(size));
}

TlsIdentity create(const std::vector<std::string>& addresses) {
  Key key(EVP_EC_gen("P-256"));
  if (!key) fail("cannot make a key");
  Cert cert(X509_new());
  if (!cert) fail("cannot make a certificate");
  X509_set_version(cert.get(), 2);  // v3, for the subjectAltName
  unsigned char serial[16];
  if (RAND_bytes(serial, sizeof serial) != 1) fail("no random serial number");
  serial[0] &= 0x7f;  // positive
  BIGNUM* number = BN_bin2bn(serial, sizeof serial, nullptr);
  BN_to_ASN1_INTEGER(number, X509_get_serialNumber(cert.get()));
  BN_free(number);
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), -3600);  // an hour of clock skew
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), long(kValidDays) * 24 * 3600);
  X509_set_pubkey(cert.get(), key.get());
  X509_NAME* name = X509_get_subject_name(cert.get());
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_ASC, reinterpret_cast<const unsigned char*>("vrdeform serve"), -1, -1,
                             0);
  X509_set_issuer_name(cert.get(), name);
  std::string names = "DNS:localhost,IP:127.0.0.1,IP:::1";
  for (const std::string& a : addresses)
    if (a != "127.0.0.1" && a != "::1") names += ",IP:" + a;
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, cert.get(), cert.get(), nullptr, nullptr, 0);
  for (const auto& [nid, value] : {std::pair{NID_subject_alt_name, names},
                                   {NID_basic_constraints, "critical,CA:FALSE"},
                                   {NID_ext_key_usage, "serverAuth"}}) {
    Extension ext(X509V3_EXT_conf_nid(nullptr, &ctx, nid, value.c_str()));
    if (!ext || !X509_add_ext(cert.get(), ext.get(), -1)) fail("cannot add an extension");
  }
  if (!X509_sign(cert.get(), key.get(), EVP_sha256())) fail("cannot sign the certificate");

  TlsIdentity id;
  id.certificatePem = pemOf([&](BIO* b) { return PEM_write_bio_X509(b, cert.get()); });
  id.privateKeyPem =
      pemOf([&](BIO* b) { return PEM_write_bio_PrivateKey(b, key.get(), nullptr, nullptr, 0, nullptr, nullptr); });
  describe(id, cert.get(), key.get());
  id.created = true;
  return id;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot read", path.string()));
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TlsIdentity read(const fs::path& certFile, const fs::path& keyFile) {
  TlsIdentity id;
  id.certificatePem = readText(certFile);
  id.privateKeyPem = readText(keyFile);
  Bio certBio(BIO_new_mem_buf(id.certificatePem.data(), int(id.certificatePem.size())));
  Cert cert(PEM_read_bio_X509(certBio.get(), nullptr, nullptr, nullptr));
  if (!cert) throw Error(fmt::format("{}: not a PEM certificate ({})", certFile.string(), openSslError()));
  Bio keyBio(BIO_new_mem_buf(id.privateKeyPem.data(), int(id.privateKeyPem.size())));
  Key key(PEM_read_bio_PrivateKey(keyBio.get(), nullptr, nullptr, nullptr));
  if (!key) throw Error(fmt::format("{}: not a PEM private key ({})", keyFile.string(), openSslError()));
  if (X509_check_private_key(cert.get(), key.get()) != 1)
    throw Error(fmt::format("{} and {} do not belong together (the key is not the certificate's)", keyFile.string(),
                            certFile.string()));
  describe(id, cert.get(), X509_get0_pubkey(cert.get()));
  return id;
}

}  // namespace

TlsIdentity loadOrCreateTlsIdentity(const fs::path& folder, const std::vector<std::string>& addresses) {
  const fs::path certFile = folder / "cert.pem", keyFile = folder / "key.pem";
  std::error_code ec;
  const bool haveCert = fs::exists(certFile, ec), haveKey = fs::exists(keyFile, ec);
  if (haveCert && haveKey) return read(certFile, keyFile);
  if (haveCert || haveKey)
    throw Error(fmt::format("{}: has {} but not {}; remove it to make a new pair", folder.string(),
                            (haveCert ? certFile : keyFile).filename().string(),
                            (haveCert ? keyFile : certFile).filename().string()));
  fs::create_directories(folder, ec);
  if (ec) throw Error(fmt::format("{}: cannot make the folder: {}", folder.string(), ec.message()));
  fs::permissions(folder, fs::perms::owner_all, ec);  // the key inside is for its owner only
  TlsIdentity id = create(addresses);
  writeFile(keyFile, id.privateKeyPem);
  fs::permissions(keyFile, fs::perms::owner_read | fs::perms::owner_write, ec);
  writeFile(certFile, id.certificatePem);
  return id;
}

fs::path defaultTlsFolder() {
  if (const char* config = std::getenv("XDG_CONFIG_HOME"); config && *config) return fs::path(config) / "vrdeform/tls";
  const char* home = std::getenv("HOME");
  return fs::path(home && *home ? home : ".") / ".config/vrdeform/tls";
}

}  // namespace vrd
