//! EtherCAT on a real Linux network interface: raw Ethernet frames of
//! EtherType 0x88A4 go through the slaves of a segment and back out of
//! the same interface, as from the last slave of a line.

use crate::eeprom_file::EepromFile;
use std::collections::BTreeMap;
use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use tmclsim_ethercat::Segment;
use tmclsim_firmware::Eeprom;
use tmclsim_host::eeprom_files::EepromFiles;

const ETH_P_ALL: u16 = 0x0003;
const PACKET_OUTGOING: u8 = 4;

/// A segment served on an interface; dropping it stops it.
pub struct EthercatHandle {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
    /// Saves EEPROM writes; ends once the frame thread has ended and
    /// every write it handed over is saved.
    saver: Option<std::thread::JoinHandle<()>>,
    /// The slaves, shared with the frame thread.
    pub segment: Arc<Mutex<Segment>>,
    /// Frames processed and frames ignored (not EtherCAT or malformed).
    pub counters: Arc<Mutex<(u64, u64)>>,
}

impl EthercatHandle {
    /// Stops the frame thread and waits until every EEPROM write is saved.
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        self.join();
    }

    /// Waits, without asking it to stop, until the frame thread ends and
    /// every EEPROM write is saved.
    pub fn wait(mut self) {
        self.join();
    }

    fn join(&mut self) {
        for t in [self.thread.take(), self.saver.take()].into_iter().flatten() {
            let _ = t.join();
        }
    }
}

impl Drop for EthercatHandle {
    fn drop(&mut self) {
        self.shutdown();
    }
}

fn check(r: libc::c_int) -> io::Result<libc::c_int> {
    if r < 0 { Err(io::Error::last_os_error()) } else { Ok(r) }
}

/// Opens a raw packet socket on `iface`.
fn open(iface: &str) -> io::Result<(libc::c_int, libc::c_int)> {
    let name = std::ffi::CString::new(iface).map_err(io::Error::other)?;
    // SAFETY: libc calls with valid arguments; the descriptor is owned by
    // the serving thread and closed by it.
    unsafe {
        let index = libc::if_nametoindex(name.as_ptr());
        if index == 0 {
            return Err(io::Error::new(io::ErrorKind::NotFound, format!("no network interface '{iface}'")));
        }
        let fd = check(libc::socket(libc::AF_PACKET, libc::SOCK_RAW, i32::from((ETH_P_ALL).to_be())))?;
        let mut sll: libc::sockaddr_ll = std::mem::zeroed();
        sll.sll_family = libc::AF_PACKET as u16;
        sll.sll_protocol = ETH_P_ALL.to_be();
        sll.sll_ifindex = index as i32;
        if libc::bind(fd, &sll as *const _ as *const libc::sockaddr, std::mem::size_of::<libc::sockaddr_ll>() as u32) < 0 {
            let e = io::Error::last_os_error();
            libc::close(fd);
            return Err(e);
        }
        let tv = libc::timeval { tv_sec: 0, tv_usec: 100_000 };
        libc::setsockopt(
            fd,
            libc::SOL_SOCKET,
            libc::SO_RCVTIMEO,
            &tv as *const _ as *const libc::c_void,
            std::mem::size_of::<libc::timeval>() as u32,
        );
        Ok((fd, index as i32))
    }
}

/// Serves `segment` on `iface` in a background thread, in wall-clock
/// time; module `i`'s EEPROM is saved to `eeproms[i]` after every write
/// (the files stay held until the segment stops).
///
/// Frames never wait for the disk: an EtherCAT slave controller answers
/// a frame as it passes, while the module's EEPROM write runs behind it.
/// A master's frame timeout is a few milliseconds, a synced file write
/// on a busy machine can take longer, so saves run on their own thread.
pub fn serve(iface: &str, mut segment: Segment, eeproms: Vec<Option<EepromFile>>) -> io::Result<EthercatHandle> {
    let (fd, index) = open(iface)?;
    segment.bus.set_stepped(false);
    let files = EepromFiles::new(&segment.bus, eeproms.into_iter().map(|f| f.map(Arc::new)).collect(), false);
    let stop = Arc::new(AtomicBool::new(false));
    let segment = Arc::new(Mutex::new(segment));
    let counters = Arc::new(Mutex::new((0u64, 0u64)));
    let (writes, written) = mpsc::channel::<(usize, Eeprom)>();
    let saver = {
        let segment = segment.clone();
        std::thread::Builder::new().name("tmclsim-ethercat-eeprom".into()).spawn(move || save_writes(written, files, segment))?
    };
    let (t_stop, t_segment, t_counters) = (stop.clone(), segment.clone(), counters.clone());
    let thread = std::thread::Builder::new().name("tmclsim-ethercat".into()).spawn(move || {
        realtime();
        let mut buf = vec![0u8; 2048];
        while !t_stop.load(Ordering::Relaxed) {
            // SAFETY: receiving into a buffer we own, with its length.
            let (n, pkttype) = unsafe {
                let mut from: libc::sockaddr_ll = std::mem::zeroed();
                let mut len = std::mem::size_of::<libc::sockaddr_ll>() as u32;
                let n = libc::recvfrom(fd, buf.as_mut_ptr().cast(), buf.len(), 0, &mut from as *mut _ as *mut libc::sockaddr, &mut len);
                (n, from.sll_pkttype)
            };
            if n <= 0 || pkttype == PACKET_OUTGOING {
                continue;
            }
            let frame = &mut buf[..n as usize];
            if frame.len() < 14 || u16::from_be_bytes([frame[12], frame[13]]) != tmclsim_ethercat::frame::ETHERTYPE {
                continue;
            }
            let processed = {
                let mut seg = t_segment.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                let processed = seg.process(frame);
                // Effects: EEPROM writes go to the saver; events have no link.
                for i in seg.bus.take_effects().eeprom_written {
                    let _ = writes.send((i, seg.bus.module(i).eeprom().clone()));
                }
                processed
            };
            {
                let mut c = t_counters.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                if processed { c.0 += 1 } else { c.1 += 1 }
            }
            if !processed {
                continue;
            }
            // SAFETY: sending a buffer we own to the interface we are bound to.
            unsafe {
                let mut to: libc::sockaddr_ll = std::mem::zeroed();
                to.sll_family = libc::AF_PACKET as u16;
                to.sll_ifindex = index;
                to.sll_halen = 6;
                libc::sendto(
                    fd,
                    frame.as_ptr().cast(),
                    frame.len(),
                    0,
                    &to as *const _ as *const libc::sockaddr,
                    std::mem::size_of::<libc::sockaddr_ll>() as u32,
                );
            }
        }
        // SAFETY: the thread owns the descriptor.
        unsafe {
            libc::close(fd);
        }
    })?;
    Ok(EthercatHandle { stop, thread: Some(thread), saver: Some(saver), segment, counters })
}

/// Puts the calling thread at a real-time priority where the process may
/// (root, or CAP_SYS_NICE; serving a raw interface needs CAP_NET_RAW
/// anyway): a slave controller answers a frame as it passes, and a master
/// gives up on a frame after a few milliseconds, so busy processes on the
/// machine must not keep the frame waiting. The thread blocks on the
/// socket between frames and works for microseconds per frame. Elsewhere
/// it stays at the normal priority.
fn realtime() {
    // SAFETY: an all-zero sched_param is valid (the C library's other
    // fields, where it has any, mean "unused" at zero).
    let mut param: libc::sched_param = unsafe { std::mem::zeroed() };
    param.sched_priority = 10;
    // SAFETY: sets the scheduling of this thread with a valid parameter.
    let _ = unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
}

/// Saves each module's EEPROM writes to its file, the newest image of a
/// module when several wait. A save that fails puts the module back to
/// what its file holds (docs/behaviour.md rule 82). Returns when the
/// frame thread has ended and nothing waits.
fn save_writes(written: mpsc::Receiver<(usize, Eeprom)>, mut files: EepromFiles, segment: Arc<Mutex<Segment>>) {
    while let Ok(first) = written.recv() {
        let mut newest: BTreeMap<usize, Eeprom> = BTreeMap::new();
        newest.extend(std::iter::once(first).chain(written.try_iter()));
        for (i, image) in newest {
            if !files.save(i, &image) {
                let mut seg = segment.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                seg.bus.module_mut(i).restore_eeprom(files.held(i).clone());
            }
        }
    }
}
