#if canImport(Network)
import Foundation
import Network
import SoftDecaCapture

/// `DatagramTransport` over Network.framework (the app's sender): a UDP `NWConnection` to a
/// numeric address. Sends are asynchronous; a failure is reported by the next `send`. Replies
/// (the receiver's requests) are queued for `poll`.
public final class NetworkTransport: DatagramTransport, @unchecked Sendable {
    private let connection: NWConnection
    private let queue = DispatchQueue(label: "softdeca.capture.udp")
    private let lock = NSLock()
    private var inbox: [[UInt8]] = []
    private var pendingError: String?

    public init(host: String, port: UInt16) throws {
        guard NumericAddress(host) != nil else {
            throw CaptureError.invalidConfiguration("'\(host)' is no numeric IPv4 or IPv6 address")
        }
        guard let p = NWEndpoint.Port(rawValue: port), port != 0 else {
            throw CaptureError.invalidConfiguration("port \(port) is no receiver port")
        }
        let params = NWParameters.udp
        params.serviceClass = .interactiveVideo  // low-latency queueing on Wi-Fi
        connection = NWConnection(host: NWEndpoint.Host(host), port: p, using: params)
        connection.stateUpdateHandler = { [weak self] state in
            if case .failed(let error) = state { self?.fail("connection failed: \(error)") }
        }
        connection.start(queue: queue)
        receiveNext()
    }

    deinit { connection.cancel() }

    public func send(_ datagram: [UInt8]) throws {
        if let e = takeError() { throw CaptureError.network(e) }
        connection.send(content: Data(datagram), completion: .contentProcessed { [weak self] error in
            if let error { self?.fail("send failed: \(error)") }
        })
    }

    public func poll() -> [UInt8]? {
        lock.lock()
        defer { lock.unlock() }
        return inbox.isEmpty ? nil : inbox.removeFirst()
    }

    public func close() { connection.cancel() }

    private func receiveNext() {
        connection.receiveMessage { [weak self] data, _, _, error in
            guard let self else { return }
            if let data, !data.isEmpty {
                self.lock.lock()
                if self.inbox.count < 64 { self.inbox.append([UInt8](data)) }
                self.lock.unlock()
            }
            if error == nil { self.receiveNext() }
        }
    }

    private func fail(_ text: String) {
        lock.lock()
        pendingError = text
        lock.unlock()
    }

    private func takeError() -> String? {
        lock.lock()
        defer { lock.unlock() }
        let e = pendingError
        pendingError = nil
        return e
    }
}
#endif
