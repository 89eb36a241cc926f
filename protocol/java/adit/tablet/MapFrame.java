// Where a session's poses and tiles lie in its map frame: the two rigid
// transforms of a frame_t (map <- odometry for poses, map <- tiles for tile
// points), applied as the console and `adit download` apply them
// (docs/PROTOCOL.md, "Frames"). Poses and tiles arrive in the odometry frame;
// once the session is anchored to a prior map, or the loop closure corrects
// it, the map frame is where a crew wants them drawn.
package adit.tablet;

public final class MapFrame {
    private static final String[] SOURCES = {"ODOMETRY", "PRIOR_MAP", "LOOPS"};

    public final String sessionId;
    public final byte source;
    private final double[] position;     // map <- odometry
    private final double[] orientation;  // w, x, y, z
    private final double[] tilesPosition;
    private final double[] tilesOrientation;

    /** The identity frame: poses and tiles where they came. */
    public static final MapFrame IDENTITY = new MapFrame("", adit.frame_t.SOURCE_ODOMETRY,
        new double[3], new double[] {1, 0, 0, 0}, new double[3], new double[] {1, 0, 0, 0});

    private MapFrame(String sessionId, byte source, double[] position, double[] orientation, double[] tilesPosition,
        double[] tilesOrientation) {
        this.sessionId = sessionId;
        this.source = source;
        this.position = position.clone();
        this.orientation = normalised(orientation);
        this.tilesPosition = tilesPosition.clone();
        this.tilesOrientation = normalised(tilesOrientation);
    }

    /** A frame_t's transforms; schema 1 had no tiles' own, so its tiles move with the poses. */
    public static MapFrame of(adit.frame_t f) {
        return f.schema < 2
            ? new MapFrame(f.session_id, f.source, f.position, f.orientation, f.position, f.orientation)
            : new MapFrame(f.session_id, f.source, f.position, f.orientation, f.tiles_position, f.tiles_orientation);
    }

    public String sourceName() {
        return source >= 0 && source < SOURCES.length ? SOURCES[source] : "source " + source;
    }

    /** A pose_t's position (odometry frame) in the map frame. */
    public double[] positionInMap(double[] odometryPosition) {
        return add(rotate(orientation, odometryPosition), position);
    }

    /** A pose_t's orientation (odometry <- body, w x y z) as map <- body. */
    public double[] orientationInMap(double[] odometryOrientation) {
        return multiply(orientation, odometryOrientation);
    }

    /** A tile point (the tiles' frame) in the map frame. */
    public double[] tilePointInMap(double[] tilePoint) {
        return add(rotate(tilesOrientation, tilePoint), tilesPosition);
    }

    private static double[] normalised(double[] q) {
        double n = Math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!(n > 0)) return new double[] {1, 0, 0, 0};  // an unset quaternion: identity, never NaN
        return new double[] {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
    }

    private static double[] add(double[] a, double[] b) {
        return new double[] {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    }

    // Hamilton product, w x y z.
    private static double[] multiply(double[] a, double[] b) {
        return new double[] {
            a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
    }

    // q·v·q*, as v + 2w(u × v) + 2u × (u × v) with u the vector part.
    private static double[] rotate(double[] q, double[] v) {
        double w = q[0], x = q[1], y = q[2], z = q[3];
        double cx = y * v[2] - z * v[1], cy = z * v[0] - x * v[2], cz = x * v[1] - y * v[0];
        return new double[] {
            v[0] + 2 * (w * cx + y * cz - z * cy),
            v[1] + 2 * (w * cy + z * cx - x * cz),
            v[2] + 2 * (w * cz + x * cy - y * cx)};
    }
}
