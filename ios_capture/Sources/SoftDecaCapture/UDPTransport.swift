#if canImport(Glibc)
import Glibc
#elseif canImport(Musl)
import Musl
#elseif canImport(Darwin)
import Darwin
#endif

/// Where datagrams go: a POSIX socket here, Network.framework in the app (SoftDecaCaptureUI).
public protocol DatagramTransport: AnyObject {
    /// Sends one datagram; throws `CaptureError.network` when the system refuses it.
    func send(_ datagram: [UInt8]) throws
    /// A datagram from the receiver (requests), nil when none is waiting. Never blocks.
    func poll() -> [UInt8]?
    func close()
}

/// A numeric IPv4 or IPv6 address, parsed with `inet_pton`.
public struct NumericAddress: Equatable, Sendable {
    public enum Family: Sendable { case ipv4, ipv6 }
    public let text: String
    public let family: Family
    let bytes: [UInt8]

    public init?(_ text: String) {
        var v4 = in_addr()
        var v6 = in6_addr()
        if inet_pton(AF_INET, text, &v4) == 1 {
            family = .ipv4
            bytes = withUnsafeBytes(of: v4) { Array($0) }
        } else if inet_pton(AF_INET6, text, &v6) == 1 {
            family = .ipv6
            bytes = withUnsafeBytes(of: v6) { Array($0) }
        } else {
            return nil
        }
        self.text = text
    }

    public var isLoopback: Bool {
        family == .ipv4 ? bytes[0] == 127 : bytes == [UInt8](repeating: 0, count: 15) + [1]
    }
}

/// A connected UDP socket (Glibc on Linux, Darwin on Apple platforms).
public final class POSIXUDPTransport: DatagramTransport {
    private var fd: Int32
    public let destination: String

    public init(host: String, port: UInt16) throws {
        guard let address = NumericAddress(host) else {
            throw CaptureError.invalidConfiguration("'\(host)' is no numeric IPv4 or IPv6 address")
        }
        guard port != 0 else { throw CaptureError.invalidConfiguration("port 0 is no receiver port") }
        destination = address.family == .ipv6 ? "[\(host)]:\(port)" : "\(host):\(port)"
        #if os(Linux)
        let datagram = Int32(SOCK_DGRAM.rawValue)
        #else
        let datagram = SOCK_DGRAM
        #endif
        fd = socket(address.family == .ipv4 ? AF_INET : AF_INET6, datagram, 0)
        guard fd >= 0 else { throw CaptureError.network("cannot open a UDP socket: \(Self.errorText())") }
        // Non-blocking: a full send buffer drops a frame instead of stalling the capture thread.
        _ = fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK)
        let rc: Int32
        switch address.family {
        case .ipv4:
            var a = sockaddr_in()
            a.sin_family = sa_family_t(AF_INET)
            a.sin_port = port.bigEndian
            withUnsafeMutableBytes(of: &a.sin_addr) { $0.copyBytes(from: address.bytes) }
            rc = connectSocket(fd, &a)
        case .ipv6:
            var a = sockaddr_in6()
            a.sin6_family = sa_family_t(AF_INET6)
            a.sin6_port = port.bigEndian
            withUnsafeMutableBytes(of: &a.sin6_addr) { $0.copyBytes(from: address.bytes) }
            rc = connectSocket(fd, &a)
        }
        guard rc == 0 else {
            let text = Self.errorText()
            _ = systemClose(fd)
            throw CaptureError.network("cannot address \(destination): \(text)")
        }
    }

    deinit { close() }

    public func send(_ datagram: [UInt8]) throws {
        guard fd >= 0 else { throw CaptureError.network("the socket to \(destination) is closed") }
        let n = datagram.withUnsafeBytes { sendto(fd, $0.baseAddress, $0.count, 0, nil, 0) }
        guard n == datagram.count else {
            throw CaptureError.network("sending \(datagram.count) bytes to \(destination) failed: \(Self.errorText())")
        }
    }

    public func poll() -> [UInt8]? {
        guard fd >= 0 else { return nil }
        var buffer = [UInt8](repeating: 0, count: 2048)
        let n = buffer.withUnsafeMutableBytes { recv(fd, $0.baseAddress, $0.count, 0) }
        return n > 0 ? Array(buffer.prefix(n)) : nil
    }

    public func close() {
        if fd >= 0 {
            _ = systemClose(fd)
            fd = -1
        }
    }

    static func errorText() -> String { String(cString: strerror(errno)) }
}

/// `connect` for a `sockaddr_in` or `sockaddr_in6` (on Apple platforms with its length set).
func connectSocket<Address>(_ fd: Int32, _ address: inout Address) -> Int32 {
    let size = MemoryLayout<Address>.size
    #if canImport(Darwin)
    withUnsafeMutableBytes(of: &address) { $0[0] = UInt8(size) }  // sin_len / sin6_len
    #endif
    return withUnsafePointer(to: &address) {
        $0.withMemoryRebound(to: sockaddr.self, capacity: 1) { connect(fd, $0, socklen_t(size)) }
    }
}

/// `close` is shadowed by the transport's own method.
@inline(__always) func systemClose(_ fd: Int32) -> Int32 {
    #if canImport(Glibc)
    return Glibc.close(fd)
    #elseif canImport(Musl)
    return Musl.close(fd)
    #else
    return Darwin.close(fd)
    #endif
}
