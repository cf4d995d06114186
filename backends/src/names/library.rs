//! The names of the C and POSIX libraries that a function of a generated file may not take
//! (issue 47): [`library_reason`], used by [`super::reserved_symbol_reason`].
//!
//! A generated file's functions have external linkage and its header declares them, so a name
//! the program's libraries declare or export breaks the program: `void printf(const double
//! *restrict in, double *restrict out)` is a conflicting declaration beside `<stdio.h>` (and
//! one of GCC's built-in functions), and a generated `time` linked into a program that calls
//! `time(NULL)` takes that call (the program crashes). A name is the library's when:
//! - [`HEADERS`] lists it: every identifier the C standard library declares (C89–C23 with
//!   Annex K) that no family below covers, and those of POSIX.1-2017 with XSI and of glibc:
//!   read from glibc 2.36's standard and POSIX headers in GCC's default dialect, in C11 with
//!   `_XOPEN_SOURCE=700` and with `_GNU_SOURCE`, and from its `<err.h>`, `<getopt.h>`,
//!   `<sys/ioctl.h>`, `<sys/epoll.h>` and a few more: every macro they define (a function named
//!   like an object-like macro is another name where the header is included; `d_fileno` is
//!   `d_ino`), every other identifier with which a declaration `void NAME(const double *in,
//!   double *out);` after them does not compile (functions, variables, types, enumeration
//!   constants; a member's name compiles), and every symbol `libc.so.6`, `libm.so.6`,
//!   `libpthread.so.0`, `libdl.so.2` and `librt.so.1` export (a program's own definition would
//!   take the library's calls);
//! - it is a variant of a name of the library: `_r`, `_l` (locale), `_s` (Annex K),
//!   `_unlocked` or `64` (large files) appended (`gmtime_r`, `isalpha_l`, `fopen_s`,
//!   `fopen64`; [`VARIANTS`], checked by [`super::reserved_symbol_reason`]);
//! - it is in a family the C standard reserves for its headers (C23 §7.1.3 and §7.33, *Future
//!   library directions*) or POSIX for its own (XSH §2.2.2, *The Name Space*): [`FAMILIES`],
//!   e.g. `str`/`mem`/`wcs`/`is`/`to` then a lowercase letter, `E` then a digit or an
//!   uppercase letter, `SIG` then an uppercase letter, `atomic_`, `memory_order_`, `cnd_`,
//!   `mtx_`, `thrd_`, `tss_`, `stdc_`, `ckd_`, `cr_`, `fe` then a lowercase letter,
//!   `pthread_`, `posix_`, `sem_`, `sched_`, `clock_`, `timer_`, `O_`/`F_`/`S_` then an
//!   uppercase letter. (`<math.h>`'s functions with their suffixes, the `_t` types and the
//!   families of the macros the file's own headers define are in [`super`].)
//!
//! The lists keep the names no family covers; `tests/c_names.rs` checks the rule against the
//! machine's own headers (every identifier they declare, in three dialects, as the name of a
//! generated function: the file compiles beside all of them).

use std::collections::HashMap;
use std::sync::OnceLock;

/// Who declares the names of a [`Header`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Origin {
    /// The C standard library (C89–C23, Annex K).
    C,
    /// POSIX.1-2017 with the XSI option.
    Posix,
    /// glibc beyond POSIX: its BSD, SVID and GNU extensions, and the symbols its libraries
    /// export.
    Glibc,
}

/// The names of one header (or, `libc.so.6`, of the exports of glibc's libraries that no
/// header of the list declares), whitespace-separated.
struct Header {
    /// `<stdio.h>`, or `libc.so.6`.
    header: &'static str,
    /// Who declares them.
    origin: Origin,
    /// The names, separated by spaces.
    names: &'static str,
}

use Header as H;
use Origin::{Glibc, Posix, C};

/// The library's names that no family of [`FAMILIES`] (nor of [`super`]) covers, by header
/// (module doc).
#[rustfmt::skip]
const HEADERS: &[Header] = &[
    H { header: "<complex.h>", origin: C, names: "CMPLX CMPLXF CMPLXL complex I imaginary" },
    H { header: "<float.h>", origin: C, names: "DECIMAL_DIG" },
    H { header: "<inttypes.h>", origin: C, names: "imaxabs imaxdiv" },
    H { header: "<iso646.h>", origin: C, names: "and and_eq bitand bitor compl not not_eq or or_eq xor xor_eq" },
    H { header: "<limits.h>", origin: C, names: "CHAR_BIT" },
    H { header: "<locale.h>", origin: C, names: "localeconv setlocale" },
    H { header: "<setjmp.h>", origin: C, names: "jmp_buf longjmp setjmp" },
    H { header: "<signal.h>", origin: C, names: "raise signal" },
    H { header: "<stdarg.h>", origin: C, names: "va_arg va_copy va_end va_list va_start" },
    H { header: "<stdatomic.h>", origin: C, names: "kill_dependency memory_order" },
    H { header: "<stddef.h>", origin: C, names: "unreachable" },
    H { header: "<stdio.h>", origin: C, names: "BUFSIZ clearerr fclose fflush fgetc fgetpos fgets FILE fopen fprintf fputc fputs fread freopen \
         fscanf fseek fsetpos ftell fwrite getc getchar gets L_tmpnam L_tmpnam_s perror printf putc \
         putchar puts remove rename rewind scanf setbuf setvbuf snprintf sprintf sscanf TMP_MAX_S tmpfile \
         tmpnam ungetc vfprintf vfscanf vprintf vscanf vsnprintf vsprintf vsscanf" },
    H { header: "<stdlib.h>", origin: C, names: "abort_handler_s ignore_handler_s set_constraint_handler_s" },
    H { header: "<threads.h>", origin: C, names: "call_once once_flag ONCE_FLAG_INIT TSS_DTOR_ITERATIONS" },
    H { header: "<time.h>", origin: C, names: "asctime clock ctime difftime gmtime gmtime_r localtime localtime_r mktime time timegm \
         timespec_get timespec_getres" },
    H { header: "<uchar.h>", origin: C, names: "c16rtomb c32rtomb c8rtomb mbrtoc16 mbrtoc32 mbrtoc8" },
    H { header: "<wchar.h>", origin: C, names: "btowc fgetwc fgetws fputwc fputws fwide fwprintf fwscanf getwc getwchar mbrlen mbrtowc mbsinit \
         mbsrtowcs putwc putwchar snwprintf_s swprintf swscanf ungetwc vfwprintf vfwscanf vsnwprintf_s \
         vswprintf vswscanf vwprintf vwscanf wcrtomb wctob wmemchr wmemcmp wmemcpy wmemmove wmemset \
         wprintf wscanf" },
    H { header: "<wctype.h>", origin: C, names: "wctrans wctype WEOF" },
    H { header: "<aio.h>", origin: Posix, names: "sigev_notify_attributes sigev_notify_function" },
    H { header: "<cpio.h>", origin: Posix, names: "C_IRGRP C_IROTH C_IRUSR C_ISBLK C_ISCHR C_ISCTG C_ISDIR C_ISFIFO C_ISGID C_ISLNK C_ISREG \
         C_ISSOCK C_ISUID C_ISVTX C_IWGRP C_IWOTH C_IWUSR C_IXGRP C_IXOTH C_IXUSR MAGIC" },
    H { header: "<dirent.h>", origin: Posix, names: "alphasort closedir d_fileno DIR dirfd fdopendir opendir readdir rewinddir scandir seekdir \
         telldir" },
    H { header: "<dlfcn.h>", origin: Posix, names: "dlclose dlerror dlopen dlsym" },
    H { header: "<fcntl.h>", origin: Posix, names: "creat fcntl flock open openat" },
    H { header: "<fmtmsg.h>", origin: Posix, names: "fmtmsg" },
    H { header: "<fnmatch.h>", origin: Posix, names: "fnmatch" },
    H { header: "<ftw.h>", origin: Posix, names: "ftw nftw" },
    H { header: "<glob.h>", origin: Posix, names: "glob globfree" },
    H { header: "<grp.h>", origin: Posix, names: "endgrent getgrent getgrgid getgrnam setgrent" },
    H { header: "<iconv.h>", origin: Posix, names: "iconv iconv_close iconv_open" },
    H { header: "<langinfo.h>", origin: Posix, names: "ABDAY_1 ABDAY_2 ABDAY_3 ABDAY_4 ABDAY_5 ABDAY_6 ABDAY_7 ABMON_1 ABMON_10 ABMON_11 ABMON_12 \
         ABMON_2 ABMON_3 ABMON_4 ABMON_5 ABMON_6 ABMON_7 ABMON_8 ABMON_9 ALT_DIGITS AM_STR CODESET \
         CRNCYSTR D_FMT D_T_FMT DAY_1 DAY_2 DAY_3 DAY_4 DAY_5 DAY_6 DAY_7 MON_1 MON_10 MON_11 MON_12 \
         MON_2 MON_3 MON_4 MON_5 MON_6 MON_7 MON_8 MON_9 nl_langinfo NOEXPR PM_STR RADIXCHAR T_FMT \
         T_FMT_AMPM THOUSEP YESEXPR" },
    H { header: "<libgen.h>", origin: Posix, names: "basename dirname" },
    H { header: "<limits.h>", origin: Posix, names: "LONG_BIT MAX_CANON MAX_INPUT NZERO PIPE_BUF WORD_BIT" },
    H { header: "<locale.h>", origin: Posix, names: "duplocale freelocale newlocale uselocale" },
    H { header: "<math.h>", origin: Posix, names: "MAXFLOAT" },
    H { header: "<netdb.h>", origin: Posix, names: "endhostent endnetent endprotoent endservent freeaddrinfo gai_strerror getaddrinfo gethostbyaddr \
         gethostbyname gethostent getnameinfo getnetbyaddr getnetbyname getnetent getprotobyname \
         getprotobynumber getprotoent getservbyname getservbyport getservent sethostent setnetent \
         setprotoent setservent" },
    H { header: "<netinet/in.h>", origin: Posix, names: "htonl htons in6addr_any in6addr_loopback INET6_ADDRSTRLEN INET_ADDRSTRLEN ntohl ntohs s6_addr" },
    H { header: "<nl_types.h>", origin: Posix, names: "catclose catgets catopen nl_catd nl_item" },
    H { header: "<poll.h>", origin: Posix, names: "poll" },
    H { header: "<pwd.h>", origin: Posix, names: "endpwent getpwent getpwnam getpwuid setpwent" },
    H { header: "<regex.h>", origin: Posix, names: "re_syntax_options regcomp regerror regexec regfree" },
    H { header: "<search.h>", origin: Posix, names: "ACTION endorder FIND hcreate hdestroy hsearch insque leaf lfind lsearch postorder preorder \
         remque tdelete tfind tsearch twalk VISIT" },
    H { header: "<setjmp.h>", origin: Posix, names: "sigjmp_buf siglongjmp sigsetjmp" },
    H { header: "<signal.h>", origin: Posix, names: "kill killpg MINSIGSTKSZ POLL_ERR POLL_HUP POLL_IN POLL_MSG POLL_OUT POLL_PRI psiginfo psignal \
         sa_handler sa_sigaction si_addr si_addr_lsb si_arch si_band si_call_addr si_fd si_int si_lower \
         si_overrun si_pid si_pkey si_ptr si_status si_stime si_syscall si_timerid si_uid si_upper \
         si_utime si_value sigaction sigaddset sigaltstack sigdelset sigemptyset sigfillset sighold \
         sigignore siginterrupt sigismember sigpause sigpending sigprocmask sigqueue sigrelse sigset \
         sigsuspend sigtimedwait sigwait sigwaitinfo" },
    H { header: "<stdio.h>", origin: Posix, names: "ctermid dprintf fdopen fileno flockfile fmemopen fseeko ftello ftrylockfile funlockfile getdelim \
         getline L_ctermid open_memstream P_tmpdir pclose popen renameat tempnam vdprintf" },
    H { header: "<stdlib.h>", origin: Posix, names: "WEXITSTATUS WIFCONTINUED WIFEXITED WIFSIGNALED WIFSTOPPED WSTOPSIG WTERMSIG" },
    H { header: "<sys/ipc.h>", origin: Posix, names: "ftok" },
    H { header: "<sys/mman.h>", origin: Posix, names: "mlock mlockall mmap mprotect msync munlock munlockall munmap" },
    H { header: "<sys/msg.h>", origin: Posix, names: "msgctl msgget msgrcv msgsnd" },
    H { header: "<sys/resource.h>", origin: Posix, names: "getpriority getrlimit getrusage setpriority setrlimit" },
    H { header: "<sys/select.h>", origin: Posix, names: "fd_set" },
    H { header: "<sys/sem.h>", origin: Posix, names: "GETALL GETNCNT GETPID GETVAL GETZCNT semctl semget semop SETALL SETVAL" },
    H { header: "<sys/shm.h>", origin: Posix, names: "shmat shmctl shmdt shmget SHMLBA" },
    H { header: "<sys/socket.h>", origin: Posix, names: "accept bind connect getpeername getsockname getsockopt listen recv recvfrom recvmsg send sendmsg \
         sendto setsockopt shutdown sockatmark socket socketpair SOMAXCONN" },
    H { header: "<sys/stat.h>", origin: Posix, names: "chmod fchmod fchmodat fstat fstatat futimens lstat mkdir mkdirat mkfifo mkfifoat mknod mknodat \
         st_atime st_ctime st_mtime stat umask UTIME_NOW UTIME_OMIT utimensat" },
    H { header: "<sys/statvfs.h>", origin: Posix, names: "fstatvfs statvfs" },
    H { header: "<sys/time.h>", origin: Posix, names: "getitimer gettimeofday ITIMER_PROF ITIMER_REAL ITIMER_VIRTUAL setitimer utimes" },
    H { header: "<sys/times.h>", origin: Posix, names: "times" },
    H { header: "<sys/uio.h>", origin: Posix, names: "readv UIO_MAXIOV writev" },
    H { header: "<sys/utsname.h>", origin: Posix, names: "uname" },
    H { header: "<sys/wait.h>", origin: Posix, names: "wait waitid waitpid" },
    H { header: "<syslog.h>", origin: Posix, names: "closelog openlog setlogmask syslog" },
    H { header: "<tar.h>", origin: Posix, names: "AREGTYPE BLKTYPE CHRTYPE CONTTYPE DIRTYPE FIFOTYPE LNKTYPE REGTYPE SYMTYPE TGEXEC TGREAD TGWRITE \
         TMAGIC TMAGLEN TOEXEC TOREAD TOWRITE TSGID TSUID TSVTX TUEXEC TUREAD TUWRITE TVERSION TVERSLEN" },
    H { header: "<termios.h>", origin: Posix, names: "B0 B1000000 B110 B115200 B1152000 B1200 B134 B150 B1500000 B1800 B19200 B200 B2000000 B230400 \
         B2400 B2500000 B300 B3000000 B3500000 B38400 B4000000 B460800 B4800 B50 B500000 B57600 B576000 \
         B600 B75 B921600 B9600 BRKINT BS0 BS1 BSDLY cfgetispeed cfgetospeed cfsetispeed cfsetospeed \
         CLOCAL CR0 CR1 CR2 CR3 CRDLY CREAD CS5 CS6 CS7 CS8 CSIZE CSTOPB FF0 FF1 FFDLY HUPCL ICANON ICRNL \
         IEXTEN IGNBRK IGNCR IGNPAR IMAXBEL INLCR INPCK ISIG ISTRIP IUCLC IUTF8 IXANY IXOFF IXON NCCS NL0 \
         NL1 NLDLY NOFLSH OCRNL OFDEL OFILL OLCUC ONLCR ONLRET ONOCR OPOST PARENB PARMRK PARODD TAB0 TAB1 \
         TAB2 TAB3 TABDLY tcdrain tcflow tcflush tcgetattr tcgetsid tcsendbreak tcsetattr TOSTOP VDISCARD \
         VEOF VEOL VEOL2 VERASE VINTR VKILL VLNEXT VMIN VQUIT VREPRINT VSTART VSTOP VSUSP VSWTC VT0 VT1 \
         VTDLY VTIME VWERASE" },
    H { header: "<time.h>", origin: Posix, names: "daylight getdate getdate_err nanosleep timezone tzname tzset" },
    H { header: "<ulimit.h>", origin: Posix, names: "UL_GETFSIZE UL_SETFSIZE ulimit" },
    H { header: "<unistd.h>", origin: Posix, names: "access alarm chdir chown close confstr dup dup2 execl execle execlp execv execve execvp \
         faccessat fchdir fchown fchownat fdatasync fork fpathconf fsync ftruncate getcwd getegid geteuid \
         getgid getgroups gethostid gethostname getlogin getopt getpgid getpgrp getpid getppid getsid \
         getuid lchown link linkat lockf lseek nice optarg opterr optind optopt pathconf pause pipe pread \
         pwrite R_OK read readlink readlinkat rmdir setegid seteuid setgid setpgid setpgrp setregid \
         setreuid setsid setuid sleep STDERR_FILENO STDIN_FILENO STDOUT_FILENO swab symlink symlinkat \
         sync sysconf tcgetpgrp tcsetpgrp truncate ttyname unlink unlinkat W_OK write X_OK" },
    H { header: "<utime.h>", origin: Posix, names: "utime" },
    H { header: "<utmpx.h>", origin: Posix, names: "BOOT_TIME DEAD_PROCESS endutxent getutxent getutxid getutxline INIT_PROCESS LOGIN_PROCESS \
         NEW_TIME OLD_TIME pututxline setutxent USER_PROCESS" },
    H { header: "<wchar.h>", origin: Posix, names: "mbsnrtowcs open_wmemstream wcpcpy wcpncpy wcwidth" },
    H { header: "<wordexp.h>", origin: Posix, names: "wordexp wordfree" },
    H { header: "<assert.h>", origin: Glibc, names: "assert_perror" },
    H { header: "<byteswap.h>", origin: Glibc, names: "bswap_16 bswap_32 bswap_64" },
    H { header: "<complex.h>", origin: Glibc, names: "CMPLXF128 CMPLXF32 CMPLXF32X CMPLXF64X" },
    H { header: "<dirent.h>", origin: Glibc, names: "DT_BLK DT_CHR DT_DIR DT_FIFO DT_LNK DT_REG DT_SOCK DT_UNKNOWN DT_WHT DTTOIF getdents64 \
         getdirentries IFTODT MAXNAMLEN scandirat versionsort" },
    H { header: "<dlfcn.h>", origin: Glibc, names: "DL_CALL_FCT Dl_info Dl_serinfo Dl_serpath dladdr dladdr1 DLFO_EH_SEGMENT_TYPE \
         DLFO_STRUCT_HAS_EH_COUNT DLFO_STRUCT_HAS_EH_DBASE dlinfo dlmopen dlvsym LM_ID_BASE LM_ID_NEWLM" },
    H { header: "<endian.h>", origin: Glibc, names: "be16toh be32toh be64toh htobe16 htobe32 htobe64 htole16 htole32 htole64 le16toh le32toh le64toh" },
    H { header: "<err.h>", origin: Glibc, names: "err errx verr verrx vwarn vwarnx warn warnx" },
    H { header: "<errno.h>", origin: Glibc, names: "program_invocation_name program_invocation_short_name" },
    H { header: "<error.h>", origin: Glibc, names: "error error_at_line error_message_count error_one_per_line error_print_progname" },
    H { header: "<execinfo.h>", origin: Glibc, names: "backtrace backtrace_symbols backtrace_symbols_fd" },
    H { header: "<fcntl.h>", origin: Glibc, names: "DN_ACCESS DN_ATTRIB DN_CREATE DN_DELETE DN_MODIFY DN_MULTISHOT DN_RENAME \
         FALLOC_FL_COLLAPSE_RANGE FALLOC_FL_INSERT_RANGE FALLOC_FL_KEEP_SIZE FALLOC_FL_NO_HIDE_STALE \
         FALLOC_FL_PUNCH_HOLE FALLOC_FL_UNSHARE_RANGE FALLOC_FL_ZERO_RANGE fallocate FAPPEND FASYNC \
         FFSYNC FNDELAY FNONBLOCK LOCK_EX LOCK_MAND LOCK_NB LOCK_READ LOCK_RW LOCK_SH LOCK_UN LOCK_WRITE \
         MAX_HANDLE_SZ name_to_handle_at open_by_handle_at readahead RWF_WRITE_LIFE_NOT_SET \
         RWH_WRITE_LIFE_EXTREME RWH_WRITE_LIFE_LONG RWH_WRITE_LIFE_MEDIUM RWH_WRITE_LIFE_NONE \
         RWH_WRITE_LIFE_NOT_SET RWH_WRITE_LIFE_SHORT splice SPLICE_F_GIFT SPLICE_F_MORE SPLICE_F_MOVE \
         SPLICE_F_NONBLOCK sync_file_range SYNC_FILE_RANGE_WAIT_AFTER SYNC_FILE_RANGE_WAIT_BEFORE \
         SYNC_FILE_RANGE_WRITE SYNC_FILE_RANGE_WRITE_AND_WAIT tee vmsplice" },
    H { header: "<fmtmsg.h>", origin: Glibc, names: "addseverity" },
    H { header: "<getopt.h>", origin: Glibc, names: "getopt_long getopt_long_only no_argument optional_argument required_argument" },
    H { header: "<glob.h>", origin: Glibc, names: "glob_pattern_p" },
    H { header: "<grp.h>", origin: Glibc, names: "fgetgrent getgrouplist initgroups NSS_BUFLEN_GROUP putgrent setgroups" },
    H { header: "<ifaddrs.h>", origin: Glibc, names: "freeifaddrs getifaddrs ifa_broadaddr ifa_dstaddr" },
    H { header: "<langinfo.h>", origin: Glibc, names: "ALTMON_1 ALTMON_10 ALTMON_11 ALTMON_12 ALTMON_2 ALTMON_3 ALTMON_4 ALTMON_5 ALTMON_6 ALTMON_7 \
         ALTMON_8 ALTMON_9 CURRENCY_SYMBOL DECIMAL_POINT FRAC_DIGITS GROUPING MON_DECIMAL_POINT \
         MON_GROUPING MON_THOUSANDS_SEP N_CS_PRECEDES N_SEP_BY_SPACE N_SIGN_POSN NEGATIVE_SIGN NOSTR \
         P_CS_PRECEDES P_SEP_BY_SPACE P_SIGN_POSN POSITIVE_SIGN THOUSANDS_SEP YESSTR" },
    H { header: "<libintl.h>", origin: Glibc, names: "bind_textdomain_codeset bindtextdomain dcgettext dcngettext dgettext dngettext gettext ngettext \
         textdomain" },
    H { header: "<malloc.h>", origin: Glibc, names: "mallinfo mallinfo2 malloc_info malloc_stats malloc_trim malloc_usable_size mallopt pvalloc" },
    H { header: "<math.h>", origin: Glibc, names: "SNAN SNANF SNANF128 SNANF32 SNANF32X SNANF64X SNANL" },
    H { header: "<mntent.h>", origin: Glibc, names: "addmntent endmntent getmntent hasmntopt MNTOPT_DEFAULTS MNTOPT_NOAUTO MNTOPT_NOSUID MNTOPT_RO \
         MNTOPT_RW MNTOPT_SUID MNTTAB MNTTYPE_IGNORE MNTTYPE_NFS MNTTYPE_SWAP MOUNTED setmntent" },
    H { header: "<net/if.h>", origin: Glibc, names: "ifc_buf ifc_req IFHWADDRLEN IFNAMSIZ ifr_addr ifr_bandwidth ifr_broadaddr ifr_data ifr_dstaddr \
         ifr_flags ifr_hwaddr ifr_ifindex ifr_map ifr_metric ifr_mtu ifr_name ifr_netmask ifr_newname \
         ifr_qlen ifr_slave" },
    H { header: "<netdb.h>", origin: Glibc, names: "endnetgrent endrpcent gai_cancel gai_error GAI_NOWAIT gai_suspend GAI_WAIT getaddrinfo_a \
         gethostbyname2 getnetgrent getrpcbyname getrpcbynumber getrpcent h_addr h_errno herror \
         HOST_NOT_FOUND hstrerror innetgr iruserok iruserok_af NETDB_INTERNAL NETDB_SUCCESS NO_ADDRESS \
         NO_DATA NO_RECOVERY rcmd rcmd_af rexec rexec_af rresvport rresvport_af ruserok ruserok_af \
         SCOPE_DELIMITER setnetgrent setrpcent TRY_AGAIN" },
    H { header: "<netinet/in.h>", origin: Glibc, names: "bindresvport bindresvport6 getipv4sourcefilter getsourcefilter GROUP_FILTER_SIZE \
         MCAST_BLOCK_SOURCE MCAST_EXCLUDE MCAST_INCLUDE MCAST_JOIN_GROUP MCAST_JOIN_SOURCE_GROUP \
         MCAST_LEAVE_GROUP MCAST_LEAVE_SOURCE_GROUP MCAST_MSFILTER MCAST_UNBLOCK_SOURCE s6_addr16 \
         s6_addr32 setipv4sourcefilter setsourcefilter" },
    H { header: "<netinet/tcp.h>", origin: Glibc, names: "tcp_seq TH_ACK TH_FIN TH_PUSH TH_RST TH_SYN TH_URG" },
    H { header: "<poll.h>", origin: Glibc, names: "ppoll" },
    H { header: "<pty.h>", origin: Glibc, names: "forkpty openpty" },
    H { header: "<pwd.h>", origin: Glibc, names: "fgetpwent getpw NSS_BUFLEN_PASSWD putpwent" },
    H { header: "<regex.h>", origin: Glibc, names: "RE_BACKSLASH_ESCAPE_IN_LISTS RE_BK_PLUS_QM RE_CARET_ANCHORS_HERE RE_CHAR_CLASSES \
         re_compile_fastmap re_compile_pattern RE_CONTEXT_INDEP_ANCHORS RE_CONTEXT_INDEP_OPS \
         RE_CONTEXT_INVALID_DUP RE_CONTEXT_INVALID_OPS RE_DEBUG RE_DOT_NEWLINE RE_DOT_NOT_NULL \
         RE_HAT_LISTS_NOT_NEWLINE RE_ICASE RE_INTERVALS RE_INVALID_INTERVAL_ORD RE_LIMITED_OPS re_match \
         re_match_2 RE_NEWLINE_ALT RE_NO_BK_BRACES RE_NO_BK_PARENS RE_NO_BK_REFS RE_NO_BK_VBAR \
         RE_NO_EMPTY_RANGES RE_NO_GNU_OPS RE_NO_POSIX_BACKTRACKING RE_NO_SUB RE_NREGS re_search \
         re_search_2 re_set_registers re_set_syntax RE_SYNTAX_AWK RE_SYNTAX_ED RE_SYNTAX_EGREP \
         RE_SYNTAX_EMACS RE_SYNTAX_GNU_AWK RE_SYNTAX_GREP RE_SYNTAX_POSIX_AWK RE_SYNTAX_POSIX_BASIC \
         RE_SYNTAX_POSIX_EGREP RE_SYNTAX_POSIX_EXTENDED RE_SYNTAX_POSIX_MINIMAL_BASIC \
         RE_SYNTAX_POSIX_MINIMAL_EXTENDED RE_SYNTAX_SED RE_TRANSLATE_TYPE RE_UNMATCHED_RIGHT_PAREN_ORD \
         REGS_FIXED REGS_REALLOCATE REGS_UNALLOCATED" },
    H { header: "<sched.h>", origin: Glibc, names: "clone CLONE_CHILD_CLEARTID CLONE_CHILD_SETTID CLONE_DETACHED CLONE_FILES CLONE_FS CLONE_IO \
         CLONE_NEWCGROUP CLONE_NEWIPC CLONE_NEWNET CLONE_NEWNS CLONE_NEWPID CLONE_NEWTIME CLONE_NEWUSER \
         CLONE_NEWUTS CLONE_PARENT CLONE_PARENT_SETTID CLONE_PIDFD CLONE_PTRACE CLONE_SETTLS \
         CLONE_SIGHAND CLONE_SYSVSEM CLONE_THREAD CLONE_UNTRACED CLONE_VFORK CLONE_VM CPU_ALLOC \
         CPU_ALLOC_SIZE CPU_AND CPU_AND_S CPU_CLR CPU_CLR_S CPU_COUNT CPU_COUNT_S CPU_EQUAL CPU_EQUAL_S \
         CPU_FREE CPU_ISSET CPU_ISSET_S CPU_OR CPU_OR_S CPU_SET CPU_SET_S CPU_SETSIZE CPU_XOR CPU_XOR_S \
         CPU_ZERO CPU_ZERO_S CSIGNAL getcpu setns unshare" },
    H { header: "<search.h>", origin: Glibc, names: "tdestroy" },
    H { header: "<shadow.h>", origin: Glibc, names: "endspent fgetspent getspent getspnam lckpwdf putspent setspent sgetspent SHADOW ulckpwdf" },
    H { header: "<signal.h>", origin: Glibc, names: "gsignal NGREG NSIG sigandset sigblock siggetmask sigisemptyset sigmask sigorset sigreturn \
         sigsetmask sigstack ssignal sysv_signal tgkill" },
    H { header: "<stdio.h>", origin: Glibc, names: "asprintf cuserid fcloseall fopencookie getw L_cuserid obstack_printf obstack_vprintf putw \
         RENAME_EXCHANGE RENAME_NOREPLACE RENAME_WHITEOUT renameat2 setbuffer setlinebuf vasprintf" },
    H { header: "<stdlib.h>", origin: Glibc, names: "canonicalize_file_name getpt" },
    H { header: "<string.h>", origin: Glibc, names: "rawmemchr sigabbrev_np sigdescr_np" },
    H { header: "<sys/epoll.h>", origin: Glibc, names: "epoll_create epoll_create1 epoll_ctl epoll_pwait epoll_pwait2 epoll_wait" },
    H { header: "<sys/eventfd.h>", origin: Glibc, names: "eventfd eventfd_read eventfd_write" },
    H { header: "<sys/file.h>", origin: Glibc, names: "L_INCR L_SET L_XTND" },
    H { header: "<sys/inotify.h>", origin: Glibc, names: "inotify_add_watch inotify_init inotify_init1 inotify_rm_watch" },
    H { header: "<sys/ioctl.h>", origin: Glibc, names: "FIOASYNC FIOCLEX FIONBIO FIONCLEX FIONREAD FIOQSIZE IOC_IN IOC_INOUT IOC_OUT IOCSIZE_MASK \
         IOCSIZE_SHIFT ioctl N_6PACK N_AX25 N_HCI N_HDLC N_IRDA N_MASC N_MOUSE N_PPP N_PROFIBUS_FDL \
         N_R3964 N_SLIP N_SMSBLOCK N_STRIP N_SYNC_PPP N_TTY N_X25 NCC SIOCADDDLCI SIOCADDMULTI SIOCADDRT \
         SIOCDARP SIOCDELDLCI SIOCDELMULTI SIOCDELRT SIOCDEVPRIVATE SIOCDIFADDR SIOCDRARP SIOCGARP \
         SIOCGIFADDR SIOCGIFBR SIOCGIFBRDADDR SIOCGIFCONF SIOCGIFCOUNT SIOCGIFDSTADDR SIOCGIFENCAP \
         SIOCGIFFLAGS SIOCGIFHWADDR SIOCGIFINDEX SIOCGIFMAP SIOCGIFMEM SIOCGIFMETRIC SIOCGIFMTU \
         SIOCGIFNAME SIOCGIFNETMASK SIOCGIFPFLAGS SIOCGIFSLAVE SIOCGIFTXQLEN SIOCGRARP SIOCPROTOPRIVATE \
         SIOCRTMSG SIOCSARP SIOCSIFADDR SIOCSIFBR SIOCSIFBRDADDR SIOCSIFDSTADDR SIOCSIFENCAP SIOCSIFFLAGS \
         SIOCSIFHWADDR SIOCSIFHWBROADCAST SIOCSIFLINK SIOCSIFMAP SIOCSIFMEM SIOCSIFMETRIC SIOCSIFMTU \
         SIOCSIFNAME SIOCSIFNETMASK SIOCSIFPFLAGS SIOCSIFSLAVE SIOCSIFTXQLEN SIOCSRARP SIOGIFINDEX \
         TIOCCBRK TIOCCONS TIOCEXCL TIOCGDEV TIOCGETD TIOCGEXCL TIOCGICOUNT TIOCGISO7816 TIOCGLCKTRMIOS \
         TIOCGPGRP TIOCGPKT TIOCGPTLCK TIOCGPTN TIOCGPTPEER TIOCGRS485 TIOCGSERIAL TIOCGSID TIOCGSOFTCAR \
         TIOCGWINSZ TIOCINQ TIOCLINUX TIOCM_CAR TIOCM_CD TIOCM_CTS TIOCM_DSR TIOCM_DTR TIOCM_LE TIOCM_RI \
         TIOCM_RNG TIOCM_RTS TIOCM_SR TIOCM_ST TIOCMBIC TIOCMBIS TIOCMGET TIOCMIWAIT TIOCMSET TIOCNOTTY \
         TIOCNXCL TIOCOUTQ TIOCPKT TIOCPKT_DATA TIOCPKT_DOSTOP TIOCPKT_FLUSHREAD TIOCPKT_FLUSHWRITE \
         TIOCPKT_IOCTL TIOCPKT_NOSTOP TIOCPKT_START TIOCPKT_STOP TIOCSBRK TIOCSCTTY TIOCSERCONFIG \
         TIOCSERGETLSR TIOCSERGETMULTI TIOCSERGSTRUCT TIOCSERGWILD TIOCSERSETMULTI TIOCSERSWILD TIOCSETD \
         TIOCSIG TIOCSISO7816 TIOCSLCKTRMIOS TIOCSPGRP TIOCSPTLCK TIOCSRS485 TIOCSSERIAL TIOCSSOFTCAR \
         TIOCSTI TIOCSWINSZ TIOCVHANGUP" },
    H { header: "<sys/mman.h>", origin: Glibc, names: "madvise MFD_ALLOW_SEALING MFD_CLOEXEC MFD_HUGETLB mincore mlock2 MLOCK_ONFAULT mremap \
         MREMAP_DONTUNMAP MREMAP_FIXED MREMAP_MAYMOVE pkey_alloc PKEY_DISABLE_ACCESS PKEY_DISABLE_WRITE \
         pkey_free pkey_get pkey_mprotect pkey_set process_madvise process_mrelease remap_file_pages" },
    H { header: "<sys/msg.h>", origin: Glibc, names: "msg_cbytes" },
    H { header: "<sys/random.h>", origin: Glibc, names: "getentropy getrandom GRND_INSECURE GRND_NONBLOCK GRND_RANDOM" },
    H { header: "<sys/resource.h>", origin: Glibc, names: "prlimit RLIM64_INFINITY" },
    H { header: "<sys/select.h>", origin: Glibc, names: "fd_mask" },
    H { header: "<sys/sem.h>", origin: Glibc, names: "semtimedop" },
    H { header: "<sys/sendfile.h>", origin: Glibc, names: "sendfile" },
    H { header: "<sys/signalfd.h>", origin: Glibc, names: "SFD_CLOEXEC SFD_NONBLOCK signalfd" },
    H { header: "<sys/socket.h>", origin: Glibc, names: "accept4 FIOGETOWN FIOSETOWN recvmmsg sendmmsg SIOCATMARK SIOCGPGRP SIOCGSTAMP_OLD \
         SIOCGSTAMPNS_OLD SIOCSPGRP" },
    H { header: "<sys/stat.h>", origin: Glibc, names: "ACCESSPERMS ALLPERMS DEFFILEMODE getumask lchmod statx STATX_ALL STATX_ATIME STATX_ATTR_APPEND \
         STATX_ATTR_AUTOMOUNT STATX_ATTR_COMPRESSED STATX_ATTR_DAX STATX_ATTR_ENCRYPTED \
         STATX_ATTR_IMMUTABLE STATX_ATTR_MOUNT_ROOT STATX_ATTR_NODUMP STATX_ATTR_VERITY STATX_BASIC_STATS \
         STATX_BLOCKS STATX_BTIME STATX_CTIME STATX_DIOALIGN STATX_GID STATX_INO STATX_MNT_ID STATX_MODE \
         STATX_MTIME STATX_NLINK STATX_SIZE STATX_TYPE STATX_UID" },
    H { header: "<sys/sysinfo.h>", origin: Glibc, names: "get_avphys_pages get_nprocs get_nprocs_conf get_phys_pages sysinfo" },
    H { header: "<sys/time.h>", origin: Glibc, names: "adjtime futimes futimesat lutimes settimeofday timeradd timerclear timercmp timerisset timersub \
         TIMESPEC_TO_TIMEVAL TIMEVAL_TO_TIMESPEC" },
    H { header: "<sys/timerfd.h>", origin: Glibc, names: "TFD_CLOEXEC TFD_NONBLOCK TFD_TIMER_ABSTIME TFD_TIMER_CANCEL_ON_SET timerfd_create \
         timerfd_gettime timerfd_settime" },
    H { header: "<sys/types.h>", origin: Glibc, names: "u_char u_int u_long u_short uint ulong ushort" },
    H { header: "<sys/uio.h>", origin: Glibc, names: "preadv preadv2 preadv64v2 process_vm_readv process_vm_writev pwritev pwritev2 pwritev64v2 \
         RWF_APPEND RWF_DSYNC RWF_HIPRI RWF_NOAPPEND RWF_NOWAIT RWF_SYNC" },
    H { header: "<sys/un.h>", origin: Glibc, names: "SUN_LEN" },
    H { header: "<sys/utsname.h>", origin: Glibc, names: "SYS_NMLN" },
    H { header: "<sys/wait.h>", origin: Glibc, names: "W_EXITCODE W_STOPCODE wait3 wait4 WAIT_ANY WAIT_MYPGRP WCOREDUMP" },
    H { header: "<syslog.h>", origin: Glibc, names: "vsyslog" },
    H { header: "<termios.h>", origin: Glibc, names: "CBAUD CBAUDEX CBRK CCEQ CDISCARD CDSUSP CEOF CEOL CEOT CERASE CFLUSH cfmakeraw cfsetspeed CIBAUD \
         CINTR CKILL CLNEXT CMIN CMSPAR CQUIT CREPRINT CRPRNT CRTSCTS CSTART CSTATUS CSTOP CSUSP CTIME \
         CTRL CWERASE FLUSHO PENDIN TIOCSER_TEMT TTYDEF_CFLAG TTYDEF_IFLAG TTYDEF_LFLAG TTYDEF_OFLAG \
         TTYDEF_SPEED XCASE XTABS" },
    H { header: "<time.h>", origin: Glibc, names: "ADJ_ESTERROR ADJ_FREQUENCY ADJ_MAXERROR ADJ_MICRO ADJ_NANO ADJ_OFFSET ADJ_OFFSET_SINGLESHOT \
         ADJ_OFFSET_SS_READ ADJ_SETOFFSET ADJ_STATUS ADJ_TAI ADJ_TICK ADJ_TIMECONST dysize MOD_CLKA \
         MOD_CLKB MOD_ESTERROR MOD_FREQUENCY MOD_MAXERROR MOD_MICRO MOD_NANO MOD_OFFSET MOD_STATUS \
         MOD_TAI MOD_TIMECONST STA_CLK STA_CLOCKERR STA_DEL STA_FLL STA_FREQHOLD STA_INS STA_MODE \
         STA_NANO STA_PLL STA_PPSERROR STA_PPSFREQ STA_PPSJITTER STA_PPSSIGNAL STA_PPSTIME STA_PPSWANDER \
         STA_RONLY STA_UNSYNC timelocal" },
    H { header: "<unistd.h>", origin: Glibc, names: "acct brk chroot close_range CLOSE_RANGE_CLOEXEC CLOSE_RANGE_UNSHARE closefrom copy_file_range \
         crypt daemon dup3 eaccess endusershell environ euidaccess execveat execvpe get_current_dir_name \
         getdomainname getdtablesize getpagesize getpass getresgid getresuid gettid getusershell getwd \
         group_member pipe2 profil revoke sbrk setdomainname sethostid sethostname setlogin setresgid \
         setresuid setusershell syncfs syscall TEMP_FAILURE_RETRY ttyslot ualarm usleep vfork vhangup" },
    H { header: "<utmp.h>", origin: Glibc, names: "ACCOUNTING endutent getutent getutid getutline login login_tty logout logwtmp pututline RUN_LVL \
         setutent updwtmp ut_addr UT_HOSTSIZE UT_LINESIZE ut_name UT_NAMESIZE ut_time UT_UNKNOWN ut_xtime \
         UTMP_FILE UTMP_FILENAME utmpname WTMP_FILE WTMP_FILENAME" },
    H { header: "<utmpx.h>", origin: Glibc, names: "getutmp getutmpx updwtmpx UTMPX_FILE UTMPX_FILENAME utmpxname WTMPX_FILE WTMPX_FILENAME" },
    H { header: "<wchar.h>", origin: Glibc, names: "wmempcpy" },
    H { header: "libc.so.6", origin: Glibc, names: "adjtimex advance arch_prctl argp_err_exit_status argp_error argp_failure argp_help argp_parse \
         argp_program_bug_address argp_program_version argp_program_version_hook argp_state_help \
         argp_usage argz_add argz_add_sep argz_append argz_count argz_create argz_create_sep argz_delete \
         argz_extract argz_insert argz_next argz_replace argz_stringify authdes_create authdes_getucred \
         authdes_pk_create authnone_create authunix_create authunix_create_default bdflush bsd_signal \
         callrpc capget capset cbc_crypt cfree chflags clnt_broadcast clnt_create clnt_pcreateerror \
         clnt_perrno clnt_perror clnt_spcreateerror clnt_sperrno clnt_sperror clntraw_create \
         clnttcp_create clntudp_bufcreate clntudp_create clntunix_create create_module delete_module \
         des_setparity dl_iterate_phdr dn_comp dn_expand dn_skipname ecb_crypt endaliasent endfsent \
         endsgent endttyent envz_add envz_entry envz_get envz_merge envz_remove envz_strip ether_aton \
         ether_hostton ether_line ether_ntoa ether_ntohost fanotify_init fanotify_mark fattach fchflags \
         fdetach fgetsgent fgetxattr flistxattr fremovexattr fsconfig fsetxattr fsmount fsopen fspick \
         fstatfs ftime fts64_children fts64_close fts64_open fts64_read fts64_set fts_children fts_close \
         fts_open fts_read fts_set get_kernel_syms get_myaddress getaliasbyname getaliasent getauxval \
         getcontext getfsent getfsfile getfsspec getmsg getnetname getpmsg getpublickey getrpcport gets \
         getsecretkey getsgent getsgnam getttyent getttynam getxattr gnu_dev_major gnu_dev_makedev \
         gnu_dev_minor gnu_get_libc_release gnu_get_libc_version gtty h_errlist h_nerr host2netname \
         init_module ioperm iopl key_decryptsession key_decryptsession_pk key_encryptsession \
         key_encryptsession_pk key_gendes key_get_conv key_secretkey_is_set key_setnet key_setsecret \
         klogctl lgetxattr listxattr llistxattr llseek loc1 loc2 locs lremovexattr lsetxattr makecontext \
         mallwatch mcheck mcheck_check_all mcheck_pedantic mcount modify_ldt moncontrol monstartup mount \
         mount_setattr move_mount mprobe mtrace muntrace netname2host netname2user nfsservctl \
         ns_name_compress ns_name_ntop ns_name_pack ns_name_pton ns_name_skip ns_name_uncompress \
         ns_name_unpack ntp_adjtime ntp_gettime ntp_gettimex obstack_alloc_failed_handler \
         obstack_exit_failure obstack_free open_tree parse_printf_format passwd2des personality \
         pidfd_getfd pidfd_open pidfd_send_signal pivot_root pmap_getmaps pmap_getport pmap_rmtcall \
         pmap_set pmap_unset prctl printf_size printf_size_info ptrace putmsg putpmsg putsgent \
         query_module quotactl re_comp re_exec re_max_failures reboot register_printf_function \
         register_printf_modifier register_printf_specifier register_printf_type registerrpc removexattr \
         res_dnok res_hnok res_mailok res_mkquery res_nmkquery res_nquery res_nquerydomain res_nsearch \
         res_nsend res_ownok res_query res_querydomain res_search res_send rexecoptions rpc_createerr \
         rtime ruserpass setaliasent setcontext setfsent setfsgid setfsuid setsgent setttyent setxattr \
         sgetsgent sigvec sprofil sstk statfs step stime stty svc_exit svc_fdset svc_getreq \
         svc_getreq_common svc_getreq_poll svc_getreqset svc_max_pollfd svc_pollfd svc_register svc_run \
         svc_sendreply svc_unregister svcauthdes_stats svcerr_auth svcerr_decode svcerr_noproc \
         svcerr_noprog svcerr_progvers svcerr_systemerr svcerr_weakauth svcfd_create svcraw_create \
         svctcp_create svcudp_bufcreate svcudp_create svcudp_enablecache svcunix_create svcunixfd_create \
         swapcontext swapoff swapon sys_errlist sys_nerr sys_sigabbrev sys_siglist sysctl tr_break umount \
         umount2 uselib user2netname ustat vlimit vtimes xdecrypt xdr_accepted_reply xdr_array \
         xdr_authdes_cred xdr_authdes_verf xdr_authunix_parms xdr_bool xdr_bytes xdr_callhdr xdr_callmsg \
         xdr_char xdr_cryptkeyarg xdr_cryptkeyarg2 xdr_cryptkeyres xdr_des_block xdr_double xdr_enum \
         xdr_float xdr_free xdr_getcredres xdr_hyper xdr_int xdr_key_netstarg xdr_key_netstres xdr_keybuf \
         xdr_keystatus xdr_long xdr_netnamestr xdr_netobj xdr_opaque xdr_opaque_auth xdr_pmap \
         xdr_pmaplist xdr_pointer xdr_reference xdr_rejected_reply xdr_replymsg xdr_rmtcall_args \
         xdr_rmtcallres xdr_short xdr_sizeof xdr_string xdr_u_char xdr_u_hyper xdr_u_int xdr_u_long \
         xdr_u_short xdr_union xdr_unixcred xdr_vector xdr_void xdr_wrapstring xdrmem_create \
         xdrrec_create xdrrec_endofrecord xdrrec_eof xdrrec_skiprecord xdrstdio_create xencrypt \
         xprt_register xprt_unregister" },
];

/// What may follow the prefix of a family of [`FAMILIES`].
#[derive(Clone, Copy)]
enum Next {
    /// An uppercase letter or a digit (`E2BIG`, `SIGINT`).
    Upper,
    /// A lowercase letter (`strlen`, `isnan`, `atomic_load`).
    Lower,
    /// Anything (`pthread_create`, `stdc_count_ones`).
    Any,
}

/// The families of names reserved for the libraries: `(prefix, what may follow, the
/// headers, who reserves them)` (module doc).
#[rustfmt::skip]
const FAMILIES: &[(&str, Next, &str, Origin)] = &[
    // C23 §7.33, Future library directions (and C17 §7.31).
    ("E", Next::Upper, "<errno.h>", C),
    ("FE_", Next::Upper, "<fenv.h>", C),
    ("fe", Next::Lower, "<fenv.h>", C),
    ("FLT_", Next::Upper, "<float.h>", C),
    ("DBL_", Next::Upper, "<float.h>", C),
    ("LDBL_", Next::Upper, "<float.h>", C),
    ("DEC32_", Next::Upper, "<float.h>", C),
    ("DEC64_", Next::Upper, "<float.h>", C),
    ("DEC128_", Next::Upper, "<float.h>", C),
    ("DEC_", Next::Upper, "<float.h>", C),
    ("PRI", Next::Any, "<inttypes.h>", C),
    ("SCN", Next::Any, "<inttypes.h>", C),
    ("LC_", Next::Upper, "<locale.h>", C),
    ("FP_", Next::Upper, "<math.h>", C),
    ("MATH_", Next::Upper, "<math.h>", C),
    ("cr_", Next::Any, "<math.h>", C),
    ("SIG", Next::Upper, "<signal.h>", C),
    ("SIG_", Next::Upper, "<signal.h>", C),
    ("ATOMIC_", Next::Upper, "<stdatomic.h>", C),
    ("atomic_", Next::Lower, "<stdatomic.h>", C),
    ("memory_order_", Next::Lower, "<stdatomic.h>", C),
    ("stdc_", Next::Any, "<stdbit.h>", C),
    ("ckd_", Next::Any, "<stdckdint.h>", C),
    ("str", Next::Lower, "<string.h> and <stdlib.h>", C),
    ("mem", Next::Lower, "<string.h>", C),
    ("wcs", Next::Lower, "<wchar.h>", C),
    ("is", Next::Lower, "<ctype.h> and <wctype.h>", C),
    ("to", Next::Lower, "<ctype.h> and <wctype.h>", C),
    ("cnd_", Next::Lower, "<threads.h>", C),
    ("mtx_", Next::Lower, "<threads.h>", C),
    ("thrd_", Next::Lower, "<threads.h>", C),
    ("tss_", Next::Lower, "<threads.h>", C),
    ("TIME_", Next::Upper, "<time.h>", C),
    // POSIX.1-2017 XSH §2.2.2, The Name Space (the prefixes reserved for any use, and those of
    // the headers' macros).
    ("aio_", Next::Any, "<aio.h>", Posix),
    ("lio_", Next::Any, "<aio.h>", Posix),
    ("AIO_", Next::Any, "<aio.h>", Posix),
    ("LIO_", Next::Any, "<aio.h>", Posix),
    ("F_", Next::Upper, "<fcntl.h>", Posix),
    ("O_", Next::Upper, "<fcntl.h>", Posix),
    ("S_", Next::Upper, "<fcntl.h> and <sys/stat.h>", Posix),
    ("AT_", Next::Upper, "<fcntl.h>", Posix),
    ("SEEK_", Next::Upper, "<stdio.h> and <unistd.h>", Posix),
    ("mq_", Next::Any, "<mqueue.h>", Posix),
    ("MQ_", Next::Any, "<mqueue.h>", Posix),
    ("pthread_", Next::Any, "<pthread.h>", Posix),
    ("PTHREAD_", Next::Any, "<pthread.h>", Posix),
    ("posix_", Next::Any, "every POSIX header", Posix),
    ("POSIX_", Next::Any, "every POSIX header", Posix),
    ("sched_", Next::Any, "<sched.h>", Posix),
    ("SCHED_", Next::Any, "<sched.h>", Posix),
    ("sem_", Next::Any, "<semaphore.h>", Posix),
    ("SEM_", Next::Any, "<semaphore.h> and <sys/sem.h>", Posix),
    ("shm_", Next::Any, "<sys/mman.h>", Posix),
    ("SHM_", Next::Any, "<sys/shm.h>", Posix),
    ("clock_", Next::Any, "<time.h>", Posix),
    ("timer_", Next::Any, "<time.h>", Posix),
    ("CLOCK_", Next::Any, "<time.h>", Posix),
    ("TIMER_", Next::Any, "<time.h>", Posix),
    ("MAP_", Next::Upper, "<sys/mman.h>", Posix),
    ("MCL_", Next::Upper, "<sys/mman.h>", Posix),
    ("MS_", Next::Upper, "<sys/mman.h>", Posix),
    ("PROT_", Next::Upper, "<sys/mman.h>", Posix),
    ("MADV_", Next::Upper, "<sys/mman.h>", Posix),
    ("AF_", Next::Upper, "<sys/socket.h>", Posix),
    ("PF_", Next::Upper, "<sys/socket.h>", Posix),
    ("MSG_", Next::Upper, "<sys/socket.h>", Posix),
    ("SO_", Next::Upper, "<sys/socket.h>", Posix),
    ("SOL_", Next::Upper, "<sys/socket.h>", Posix),
    ("SOCK_", Next::Upper, "<sys/socket.h>", Posix),
    ("SCM_", Next::Upper, "<sys/socket.h>", Posix),
    ("SHUT_", Next::Upper, "<sys/socket.h>", Posix),
    ("CMSG_", Next::Upper, "<sys/socket.h>", Posix),
    ("IN_", Next::Upper, "<netinet/in.h>", Posix),
    ("IN6_", Next::Upper, "<netinet/in.h>", Posix),
    ("IN6ADDR_", Next::Upper, "<netinet/in.h>", Posix),
    ("INADDR_", Next::Upper, "<netinet/in.h>", Posix),
    ("IPPROTO_", Next::Upper, "<netinet/in.h>", Posix),
    ("IPPORT_", Next::Upper, "<netinet/in.h>", Posix),
    ("IPV6_", Next::Upper, "<netinet/in.h>", Posix),
    ("IP_", Next::Upper, "<netinet/in.h>", Posix),
    ("TCP_", Next::Upper, "<netinet/tcp.h>", Posix),
    ("inet_", Next::Any, "<arpa/inet.h>", Posix),
    ("inet6_", Next::Any, "<netinet/in.h>", Posix),
    ("AI_", Next::Upper, "<netdb.h>", Posix),
    ("NI_", Next::Upper, "<netdb.h>", Posix),
    ("if_", Next::Any, "<net/if.h>", Posix),
    ("IF_", Next::Upper, "<net/if.h>", Posix),
    ("IFF_", Next::Upper, "<net/if.h>", Posix),
    ("dbm_", Next::Any, "<ndbm.h>", Posix),
    ("POLL", Next::Upper, "<poll.h>", Posix),
    ("REG_", Next::Upper, "<regex.h>", Posix),
    ("RLIM_", Next::Upper, "<sys/resource.h>", Posix),
    ("RLIMIT_", Next::Upper, "<sys/resource.h>", Posix),
    ("RUSAGE_", Next::Upper, "<sys/resource.h>", Posix),
    ("PRIO_", Next::Upper, "<sys/resource.h>", Posix),
    ("SA_", Next::Upper, "<signal.h>", Posix),
    ("SI_", Next::Upper, "<signal.h>", Posix),
    ("SS_", Next::Upper, "<signal.h>", Posix),
    ("SV_", Next::Upper, "<signal.h>", Posix),
    ("TRAP_", Next::Upper, "<signal.h>", Posix),
    ("ILL_", Next::Upper, "<signal.h>", Posix),
    ("FPE_", Next::Upper, "<signal.h>", Posix),
    ("SEGV_", Next::Upper, "<signal.h>", Posix),
    ("BUS_", Next::Upper, "<signal.h>", Posix),
    ("CLD_", Next::Upper, "<signal.h>", Posix),
    ("ST_", Next::Upper, "<sys/statvfs.h>", Posix),
    ("IPC_", Next::Upper, "<sys/ipc.h>", Posix),
    ("GLOB_", Next::Upper, "<glob.h>", Posix),
    ("FNM_", Next::Upper, "<fnmatch.h>", Posix),
    ("FTW_", Next::Upper, "<ftw.h>", Posix),
    ("WRDE_", Next::Upper, "<wordexp.h>", Posix),
    ("LOG_", Next::Upper, "<syslog.h>", Posix),
    ("MM_", Next::Upper, "<fmtmsg.h>", Posix),
    ("RTLD_", Next::Upper, "<dlfcn.h>", Posix),
    ("NL_", Next::Upper, "<nl_types.h>", Posix),
    ("TC", Next::Upper, "<termios.h>", Posix),
];

/// Functions of `<complex.h>` (C99–C23, and the names C23 §7.33.1 reserves), each also with
/// the suffixes of [`MATH_SUFFIXES`]; `<math.h>`'s are [`super`]'s.
const COMPLEX_FUNCTIONS: &[&str] = &[
    "cabs",
    "cacos",
    "cacosh",
    "carg",
    "casin",
    "casinh",
    "catan",
    "catanh",
    "ccos",
    "ccosh",
    "cexp",
    "cimag",
    "clog",
    "conj",
    "cpow",
    "cproj",
    "creal",
    "csin",
    "csinh",
    "csqrt",
    "ctan",
    "ctanh",
    "cerf",
    "cerfc",
    "cexp2",
    "cexpm1",
    "clog10",
    "clog1p",
    "clog2",
    "clgamma",
    "ctgamma",
    "cexp10",
    "cexp10m1",
    "cexp2m1",
    "clog10p1",
    "clog2p1",
    "clogp1",
    "csinpi",
    "ccospi",
    "ctanpi",
    "casinpi",
    "cacospi",
    "catanpi",
    "ccompoundn",
    "cpown",
    "cpowr",
    "crootn",
    "crsqrt",
];

/// `<math.h>`'s decimal and TS 18661 functions that [`super`]'s list lacks, each also with the
/// suffixes of [`MATH_SUFFIXES`].
const MORE_MATH_FUNCTIONS: &[&str] = &[
    "fmaxmag",
    "fminmag",
    "quantize",
    "samequantum",
    "quantum",
    "llquantexp",
    "encodedec",
    "decodedec",
    "encodebin",
    "decodebin",
];

/// The suffixes of the type-specific forms of a function of `<math.h>` or `<complex.h>`
/// (C23 and its Annex X, TS 18661-3): `sinf`, `sinl`, `sinf128`, `sind64`.
pub(super) const MATH_SUFFIXES: &[&str] =
    &["f", "l", "f16", "f32", "f64", "f128", "f32x", "f64x", "f128x", "d32", "d64", "d128", "d64x", "d128x"];

/// The suffixes of a library function's variants (module doc).
pub(super) const VARIANTS: &[&str] = &["_r", "_l", "_s", "_unlocked", "64"];

/// `name`, or `name` without one of `suffixes`, satisfies `is`.
fn with_suffixes(name: &str, suffixes: &[&str], is: impl Fn(&str) -> bool) -> bool {
    is(name) || suffixes.iter().any(|s| name.strip_suffix(s).is_some_and(|b| !b.is_empty() && is(b)))
}

/// A function of `<complex.h>` or one of `<math.h>`'s of [`MORE_MATH_FUNCTIONS`], with its
/// suffixes, or one of C23's narrowing functions (`f32addf64`, `dsqrtl`: TS 18661-3).
fn is_more_math(name: &str) -> bool {
    let listed = |b: &str| COMPLEX_FUNCTIONS.contains(&b) || MORE_MATH_FUNCTIONS.contains(&b);
    with_suffixes(name, MATH_SUFFIXES, listed) || is_narrowing(name)
}

/// `f` or `d`, a width or none (`32`, `64x`), an operation, a suffix or none: `f32addf64`,
/// `dsqrtl`, `fmul`.
fn is_narrowing(name: &str) -> bool {
    let Some(rest) = name.strip_prefix(['f', 'd']) else { return false };
    let rest = match ["128", "16", "32", "64"].iter().find_map(|w| rest.strip_prefix(w)) {
        Some(r) => r.strip_prefix('x').unwrap_or(r),
        None => rest,
    };
    ["add", "sub", "mul", "div", "fma", "sqrt"]
        .iter()
        .any(|op| rest.strip_prefix(op).is_some_and(|s| s.is_empty() || MATH_SUFFIXES.contains(&s)))
}

/// Name → index in [`HEADERS`].
fn index() -> &'static HashMap<&'static str, usize> {
    static INDEX: OnceLock<HashMap<&'static str, usize>> = OnceLock::new();
    INDEX.get_or_init(|| {
        let mut m = HashMap::new();
        for (i, h) in HEADERS.iter().enumerate() {
            for n in h.names.split_ascii_whitespace() {
                m.entry(n).or_insert(i);
            }
        }
        m
    })
}

/// The header that declares `name`, from [`HEADERS`].
fn declared(name: &str) -> Option<&'static Header> {
    index().get(name).map(|&i| &HEADERS[i])
}

/// True when `name` is in a family of [`FAMILIES`].
pub(super) fn in_family(name: &str) -> bool {
    family(name).is_some()
}

/// The family of [`FAMILIES`] `name` is in.
fn family(name: &str) -> Option<&'static (&'static str, Next, &'static str, Origin)> {
    FAMILIES.iter().find(|(p, next, _, _)| {
        name.strip_prefix(p).and_then(|r| r.chars().next()).is_some_and(|c| match next {
            Next::Upper => c.is_ascii_uppercase() || c.is_ascii_digit(),
            Next::Lower => c.is_ascii_lowercase(),
            Next::Any => true,
        })
    })
}

fn who(o: Origin) -> &'static str {
    match o {
        C => "the C standard library",
        Posix => "POSIX",
        Glibc => "glibc",
    }
}

/// Why `name` is the C or POSIX library's by [`HEADERS`], `<complex.h>`'s and `<math.h>`'s
/// further functions or [`FAMILIES`] (module doc), for a diagnostic: `None` when it is not.
pub(super) fn library_reason(name: &str) -> Option<String> {
    if let Some(h) = declared(name) {
        let how = if h.header.starts_with('<') { "declared" } else { "exported" };
        return Some(format!("{how} by {} ({})", h.header, who(h.origin)));
    }
    if is_more_math(name) {
        return Some("a function of <math.h> or <complex.h>".into());
    }
    family(name).map(|(p, next, header, o)| {
        let after = match next {
            Next::Upper => " then an uppercase letter or a digit",
            Next::Lower => " then a lowercase letter",
            Next::Any => "",
        };
        format!("reserved by {} for {header} (`{p}…`{after})", if *o == C { "the C standard" } else { "POSIX" })
    })
}
