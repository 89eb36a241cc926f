// The Java example client: `java -cp adit-lcm.jar:/usr/share/java/lcm.jar adit.tablet.AditTool
// status|watch|start|stop|ping|sessions [--payload ID] [--lcm-url URL] [--key FILE] [--timeout S]
// [--duration S]`. Exit 0 on success, 1 when rejected or unanswered, 2 for bad input.
package adit.tablet;

import java.io.IOException;
import java.nio.file.Path;

public final class AditTool {
    private static final String[] STATES = {"IDLE", "MAPPING", "STOPPING"};

    private static String state(byte s) { return s >= 0 && s < STATES.length ? STATES[s] : "state " + s; }

    public static void main(String[] argv) throws Exception {
        System.exit(run(argv));
    }

    static int run(String[] argv) throws Exception {
        if (argv.length < 1) {
            System.err.println("usage: AditTool status|watch|start|stop|ping|sessions [--payload ID] [--lcm-url URL]"
                + " [--key FILE] [--timeout S] [--duration S]");
            return 2;
        }
        String verb = argv[0];
        String payload = "adit";
        String url = AditClient.DEFAULT_URL;
        String keyFile = null;
        double timeout = 5;
        double duration = 5;
        for (int i = 1; i < argv.length; i += 2) {
            if (i + 1 >= argv.length) {
                System.err.println("AditTool: error: " + argv[i] + " needs a value");
                return 2;
            }
            switch (argv[i]) {
                case "--payload": payload = argv[i + 1]; break;
                case "--lcm-url": url = argv[i + 1]; break;
                case "--key": keyFile = argv[i + 1]; break;
                case "--timeout": timeout = Double.parseDouble(argv[i + 1]); break;
                case "--duration": duration = Double.parseDouble(argv[i + 1]); break;
                default:
                    System.err.println("AditTool: error: unknown option " + argv[i]);
                    return 2;
            }
        }
        CommandAuth.Key key = null;
        if (keyFile != null) {
            try {
                key = CommandAuth.readKeyFile(Path.of(keyFile));
            } catch (IOException e) {
                System.err.println("AditTool: error: " + e.getMessage());
                return 2;
            }
        }
        try (AditClient client = new AditClient(url, payload, key)) {
            switch (verb) {
                case "status": {
                    adit.status_t s = client.status(timeout);
                    if (s == null) return noAnswer(payload, timeout);
                    System.out.printf("payload %s state %s session %s map %d points in %d tiles%n", s.payload_id,
                        state(s.state), s.session_id.isEmpty() ? "-" : s.session_id, s.map_points, s.map_tiles);
                    for (adit.sensor_health_t h : s.sensors)
                        System.out.printf("sensor %s %.1f Hz, %d dropped%n", h.name, h.packet_rate_hz, h.packets_dropped);
                    System.out.println("fault " + (s.fault.isEmpty() ? "none" : s.fault));
                    return 0;
                }
                case "watch": {
                    // Poses arrive in the odometry frame; the session's frame_t places the last one in the map
                    // frame (a prior map's once anchored, the loop closure's correction otherwise).
                    long[] counts = new long[3];
                    adit.pose_t[] last = new adit.pose_t[1];
                    MapFrame[] frame = {MapFrame.IDENTITY};
                    client.watch(p -> {
                        synchronized (counts) {
                            ++counts[0];
                            last[0] = p;
                        }
                    }, s -> {
                        synchronized (counts) { ++counts[1]; }
                        System.out.printf("status %s %s%n", state(s.state), s.session_id.isEmpty() ? "-" : s.session_id);
                    }, f -> {
                        synchronized (counts) {
                            ++counts[2];
                            MapFrame m = MapFrame.of(f);
                            if (m.source != frame[0].source)
                                System.out.printf("frame %s session %s%n", m.sourceName(), m.sessionId);
                            frame[0] = m;
                        }
                    }, duration);
                    synchronized (counts) {
                        System.out.printf("%d poses, %d status messages, %d frames received%n", counts[0], counts[1],
                            counts[2]);
                        if (last[0] != null) {
                            // Another session's frame does not place this pose.
                            MapFrame f = frame[0].sessionId.equals(last[0].session_id) ? frame[0] : MapFrame.IDENTITY;
                            double[] o = last[0].position;
                            double[] m = f.positionInMap(o);
                            System.out.printf("last pose: odometry (%.3f, %.3f, %.3f) m, map (%.3f, %.3f, %.3f) m (%s)%n",
                                o[0], o[1], o[2], m[0], m[1], m[2], f.sourceName());
                        }
                        return counts[1] > 0 ? 0 : noAnswer(payload, duration);
                    }
                }
                case "start": case "stop": case "ping": case "sessions": {
                    adit.command_ack_t ack = client.command(verb.toUpperCase(), new String[0], timeout);
                    if (ack == null) return noAnswer(payload, timeout);
                    if (!ack.accepted) {
                        System.err.printf("AditTool: %s rejected: %s (state %s)%n", verb.toUpperCase(), ack.reason,
                            state(ack.state));
                        return 1;
                    }
                    System.out.printf("%s: %s (state %s%s)%n", verb.toUpperCase(), ack.reason, state(ack.state),
                        ack.session_id.isEmpty() ? "" : ", session " + ack.session_id);
                    if (!ack.detail.isEmpty()) System.out.print(ack.detail);
                    return 0;
                }
                default:
                    System.err.println("AditTool: error: unknown command " + verb);
                    return 2;
            }
        }
    }

    private static int noAnswer(String payload, double seconds) {
        System.err.printf("AditTool: error: no payload '%s' answered within %s s%n", payload, seconds);
        return 1;
    }
}
