// A small client of an adit payload over LCM, for tablet apps: the status,
// the live pose, status and frame stream, and commands (signed when a key is given),
// resent with the same bytes every 250 ms until acknowledged, as `adit` does
// (docs/PROTOCOL.md).
package adit.tablet;

import java.io.IOException;
import java.security.SecureRandom;
import java.util.concurrent.ArrayBlockingQueue;
import java.util.concurrent.BlockingQueue;
import java.util.concurrent.TimeUnit;
import java.util.function.Consumer;
import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;

public final class AditClient implements AutoCloseable {
    public static final String DEFAULT_URL = "udpm://239.255.76.67:7667?ttl=1";

    private final LCM lcm;
    private final String payload;
    private final CommandAuth.Key key;  // null: commands are not signed
    private final SecureRandom random = new SecureRandom();

    public AditClient(String lcmUrl, String payload, CommandAuth.Key key) throws IOException {
        this.lcm = new LCM(lcmUrl);
        this.payload = payload;
        this.key = key;
    }

    public String channel(String kind) { return "ADIT/" + payload + "/" + kind; }

    /** The next status_t, or null when none arrives within the timeout. */
    public adit.status_t status(double timeoutSeconds) throws InterruptedException {
        BlockingQueue<adit.status_t> got = new ArrayBlockingQueue<>(1);
        LCMSubscriber sub = subscriber(adit.status_t::new, got::offer);
        lcm.subscribe(channel("STATUS"), sub);
        try {
            return got.poll((long) (timeoutSeconds * 1000), TimeUnit.MILLISECONDS);
        } finally {
            lcm.unsubscribe(channel("STATUS"), sub);
        }
    }

    /** Calls the handlers (on LCM's thread) for every pose and status for `seconds`. */
    public void watch(Consumer<adit.pose_t> onPose, Consumer<adit.status_t> onStatus, double seconds)
        throws InterruptedException {
        watch(onPose, onStatus, f -> { }, seconds);
    }

    /**
     * As above, and every frame_t of this payload (2 Hz while a session runs): poses are in the odometry frame,
     * MapFrame.of(frame) places them in the map frame (a prior map's once anchored).
     */
    public void watch(Consumer<adit.pose_t> onPose, Consumer<adit.status_t> onStatus, Consumer<adit.frame_t> onFrame,
        double seconds) throws InterruptedException {
        LCMSubscriber poses = subscriber(adit.pose_t::new, onPose);
        LCMSubscriber statuses = subscriber(adit.status_t::new, onStatus);
        LCMSubscriber frames = subscriber(adit.frame_t::new, onFrame);
        lcm.subscribe(channel("POSE"), poses);
        lcm.subscribe(channel("STATUS"), statuses);
        lcm.subscribe(channel("FRAME"), frames);
        try {
            Thread.sleep((long) (seconds * 1000));
        } finally {
            lcm.unsubscribe(channel("POSE"), poses);
            lcm.unsubscribe(channel("STATUS"), statuses);
            lcm.unsubscribe(channel("FRAME"), frames);
        }
    }

    /** Sends a command and waits for its ack; null when the payload does not answer in time. */
    public adit.command_ack_t command(String verb, String[] args, double timeoutSeconds)
        throws InterruptedException {
        adit.command_t c = new adit.command_t();
        c.utime = System.currentTimeMillis() * 1000;
        c.schema = 1;
        c.request_id = 0;
        while (c.request_id <= 0) c.request_id = random.nextLong() >>> 1;
        c.payload_id = payload;
        c.verb = verb;
        c.args = args == null ? new String[0] : args.clone();
        c.n_args = c.args.length;
        c.auth = new byte[0];
        c.auth_size = 0;
        if (key != null) CommandAuth.sign(c, key);
        final long id = c.request_id;
        BlockingQueue<adit.command_ack_t> acks = new ArrayBlockingQueue<>(1);
        LCMSubscriber sub = subscriber(adit.command_ack_t::new, ack -> {
            if (ack.request_id == id) acks.offer(ack);
        });
        lcm.subscribe(channel("ACK"), sub);
        try {
            long deadline = System.nanoTime() + (long) (timeoutSeconds * 1e9);
            while (System.nanoTime() < deadline) {
                lcm.publish(channel("COMMAND"), c);  // the same bytes each time: a retry, not a new command
                adit.command_ack_t ack = acks.poll(250, TimeUnit.MILLISECONDS);
                if (ack != null) return ack;
            }
            return null;
        } finally {
            lcm.unsubscribe(channel("ACK"), sub);
        }
    }

    @Override
    public void close() { lcm.close(); }

    private interface Decoder<T> {
        T decode(LCMDataInputStream ins) throws IOException;
    }

    // Decodes each message on the channel and hands it on; one that is not of
    // the type is ignored, as the C++ client does.
    private static <T> LCMSubscriber subscriber(Decoder<T> decoder, Consumer<T> handler) {
        return (lcm, channel, ins) -> {
            try {
                handler.accept(decoder.decode(ins));
            } catch (IOException e) {
                // not a T: ignored
            }
        };
    }
}
