#pragma once
// The certificate `vrdeform serve --tls` serves HTTPS and WSS with: self-signed, made on first
// use and kept in a folder, so that a headset that accepted it once keeps accepting it. WebXR
// needs a secure context; on the local network that means TLS.

#include <filesystem>
#include <string>
#include <vector>

namespace vrd {

struct TlsIdentity {
  std::string certificatePem, privateKeyPem;
  /// SHA-256 of the certificate, "AB:CD:...": what a browser shows as its fingerprint.
  std::string fingerprint;
  /// Base64 SHA-256 of its public key: Chromium's --ignore-certificate-errors-spki-list value.
  std::string spkiHash;
  bool created = false;  ///< made by this call (else read)
};

/// The certificate and key in `folder` (cert.pem, key.pem), or, when neither is there, a new
/// self-signed pair (EC P-256, SHA-256, valid 825 days) for "localhost", 127.0.0.1, ::1 and
/// `addresses` (the machine's network addresses), written there (the key readable by its owner
/// only). Throws vrd::Error for one file without the other, unreadable or mismatched files, or a
/// folder it cannot write.
TlsIdentity loadOrCreateTlsIdentity(const std::filesystem::path& folder, const std::vector<std::string>& addresses);

/// The default folder: $XDG_CONFIG_HOME/vrdeform/tls, else ~/.config/vrdeform/tls.
std::filesystem::path defaultTlsFolder();

}  // namespace vrd
