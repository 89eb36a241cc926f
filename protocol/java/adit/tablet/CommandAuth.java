// Signing adit commands in Java (docs/COMMAND-AUTH.md):
// HMAC-SHA-256 with a pre-shared 32-byte key over the canonical bytes of a
// command_t, the same layout as protocol/src/command_auth.cpp. Java 17's own
// javax.crypto does the HMAC and SHA-256; no other library is needed.
package adit.tablet;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermission;
import java.security.GeneralSecurityException;
import java.security.MessageDigest;
import java.util.Arrays;
import java.util.EnumSet;
import java.util.List;
import java.util.Set;
import javax.crypto.Mac;
import javax.crypto.spec.SecretKeySpec;

public final class CommandAuth {
    public static final byte SCHEME_HMAC_SHA256 = 1;
    public static final int KEY_BYTES = 32;
    public static final int KEY_ID_BYTES = 8;
    public static final int AUTH_BYTES = 1 + KEY_ID_BYTES + 32;
    public static final String KEY_FILE_WORD = "adit-command-key-v1";

    /** A secret key and its public id (first 8 bytes of SHA-256("adit-command-key-id" || key)). */
    public static final class Key {
        private final byte[] secret;
        private final byte[] id;

        public Key(byte[] secret) {
            if (secret.length != KEY_BYTES) throw new IllegalArgumentException("a command key is 32 bytes");
            this.secret = secret.clone();
            try {
                MessageDigest sha = MessageDigest.getInstance("SHA-256");
                sha.update("adit-command-key-id".getBytes(StandardCharsets.US_ASCII));
                sha.update(this.secret);
                this.id = Arrays.copyOf(sha.digest(), KEY_ID_BYTES);
            } catch (GeneralSecurityException e) {
                throw new IllegalStateException(e);
            }
        }

        public byte[] id() { return id.clone(); }

        public String idHex() {
            StringBuilder s = new StringBuilder();
            for (byte b : id) s.append(String.format("%02x", b & 0xff));
            return s.toString();
        }
    }

    private CommandAuth() {}

    /**
     * Reads the first key of a key file written by `adit keygen`; refuses a file that its group or
     * others may use, as aditd and adit do.
     */
    public static Key readKeyFile(Path path) throws IOException {
        Set<PosixFilePermission> open = EnumSet.of(
            PosixFilePermission.GROUP_READ, PosixFilePermission.GROUP_WRITE, PosixFilePermission.GROUP_EXECUTE,
            PosixFilePermission.OTHERS_READ, PosixFilePermission.OTHERS_WRITE, PosixFilePermission.OTHERS_EXECUTE);
        open.retainAll(Files.getPosixFilePermissions(path));
        if (!open.isEmpty())
            throw new IOException(path + ": group or others may use the key file (" + open + "); chmod 600 " + path);
        List<String> lines = Files.readAllLines(path, StandardCharsets.US_ASCII);
        for (int n = 0; n < lines.size(); ++n) {
            String line = lines.get(n).trim();
            if (line.isEmpty() || line.startsWith("#")) continue;
            String[] words = line.split("\\s+");
            if (words.length != 2 || !words[0].equals(KEY_FILE_WORD) || words[1].length() != 2 * KEY_BYTES)
                throw new IOException(path + ":" + (n + 1) + ": expected '" + KEY_FILE_WORD + " <64 hex digits>'");
            byte[] secret = new byte[KEY_BYTES];
            try {
                for (int i = 0; i < KEY_BYTES; ++i)
                    secret[i] = (byte) Integer.parseInt(words[1].substring(2 * i, 2 * i + 2), 16);
            } catch (NumberFormatException e) {
                throw new IOException(path + ":" + (n + 1) + ": the key must be 64 hex digits");
            }
            return new Key(secret);
        }
        throw new IOException(path + ": no key in the file");
    }

    /** The bytes the tag covers: every field of the command but auth, in the documented layout. */
    public static byte[] canonicalBytes(adit.command_t c, byte[] keyId) {
        ByteArrayOutputStream out = new ByteArrayOutputStream();
        out.writeBytes("adit-command-v1".getBytes(StandardCharsets.US_ASCII));
        out.writeBytes(keyId);
        out.write(SCHEME_HMAC_SHA256);
        putLong(out, c.utime);
        out.write((c.schema >> 8) & 0xff);
        out.write(c.schema & 0xff);
        putLong(out, c.request_id);
        putString(out, c.payload_id);
        putString(out, c.verb);
        int n = c.args == null ? 0 : c.args.length;
        putInt(out, n);
        for (int i = 0; i < n; ++i) putString(out, c.args[i]);
        return out.toByteArray();
    }

    /** Fills auth/auth_size (and n_args); every other field must be final before. */
    public static void sign(adit.command_t c, Key key) {
        if (c.args == null) c.args = new String[0];
        c.n_args = c.args.length;
        byte[] id = key.id;
        byte[] tag;
        try {
            Mac mac = Mac.getInstance("HmacSHA256");
            mac.init(new SecretKeySpec(key.secret, "HmacSHA256"));
            tag = mac.doFinal(canonicalBytes(c, id));
        } catch (GeneralSecurityException e) {
            throw new IllegalStateException(e);
        }
        c.auth = new byte[AUTH_BYTES];
        c.auth[0] = SCHEME_HMAC_SHA256;
        System.arraycopy(id, 0, c.auth, 1, KEY_ID_BYTES);
        System.arraycopy(tag, 0, c.auth, 1 + KEY_ID_BYTES, tag.length);
        c.auth_size = c.auth.length;
    }

    private static void putLong(ByteArrayOutputStream out, long v) {
        for (int shift = 56; shift >= 0; shift -= 8) out.write((int) (v >>> shift) & 0xff);
    }

    private static void putInt(ByteArrayOutputStream out, int v) {
        for (int shift = 24; shift >= 0; shift -= 8) out.write((v >>> shift) & 0xff);
    }

    // lcm-gen 1.3's Java encoder writes the low byte of each char: the tag
    // covers what goes on the wire only for ASCII text, so other text is refused.
    private static void putString(ByteArrayOutputStream out, String s) {
        for (int i = 0; i < s.length(); ++i)
            if (s.charAt(i) == 0 || s.charAt(i) > 0x7f)
                throw new IllegalArgumentException("command text must be ASCII (LCM's Java encoder): " + s);
        byte[] bytes = s.getBytes(StandardCharsets.US_ASCII);
        putInt(out, bytes.length);
        out.writeBytes(bytes);
    }
}
